//! Tests of eenf-events's `rosbag2/folder` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::rosbag2::folder::*;

fn bag(listed: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("b_0.db3"), b"SQLite format 3\0").unwrap();
    let items: String = listed.iter().map(|f| format!("    - {f}\n")).collect();
    std::fs::write(
        dir.path().join("metadata.yaml"),
        format!("rosbag2_bagfile_information:\n  relative_file_paths:\n{items}  files: []\n"),
    )
    .unwrap();
    dir
}

fn refused(listed: &[&str]) -> String {
    let dir = bag(listed);
    let e = storage_files(dir.path()).unwrap_err().to_string();
    // the error names the bag, on one line
    assert!(e.starts_with(&dir.path().display().to_string()), "{e}");
    assert!(!e.contains('\n'), "{e}");
    e
}

#[test]
fn listed_files_stay_inside_the_bag() {
    let dir = bag(&["b_0.db3"]);
    assert_eq!(
        storage_files(dir.path()).unwrap(),
        vec![dir.path().join("b_0.db3")]
    );
    for outside in [
        "/etc/passwd",
        "/dev/zero",
        "../../etc/passwd",
        "./../b_0.db3",
    ] {
        let e = refused(&[outside]);
        assert!(e.contains("not a file inside the bag's folder"), "{e}");
    }
    assert!(refused(&["b_0.db3", "b_0.db3"]).contains("more than once"));
    assert!(refused(&["missing.db3"]).contains("cannot be opened"));
    // a link inside the folder that leads out of it
    let dir = bag(&["link.db3"]);
    std::os::unix::fs::symlink("/etc/passwd", dir.path().join("link.db3")).unwrap();
    assert!(storage_files(dir.path()).is_err());
    // ROS 2 Foxy listed the files under the folder's own name
    let dir = bag(&[]);
    let name = dir
        .path()
        .file_name()
        .unwrap()
        .to_str()
        .unwrap()
        .to_string();
    let yaml =
        format!("rosbag2_bagfile_information:\n  relative_file_paths:\n    - {name}/b_0.db3\n");
    std::fs::write(dir.path().join("metadata.yaml"), yaml).unwrap();
    assert_eq!(
        storage_files(dir.path()).unwrap(),
        vec![dir.path().join("b_0.db3")]
    );
}

#[test]
fn a_metadata_file_past_its_bound_is_refused_unread() {
    let dir = bag(&["b_0.db3"]);
    let big = "#".repeat(MAX_METADATA as usize + 1);
    std::fs::write(dir.path().join("metadata.yaml"), big).unwrap();
    let e = storage_files(dir.path()).unwrap_err().to_string();
    assert!(e.contains("larger than 1024 KiB"), "{e}");
}
