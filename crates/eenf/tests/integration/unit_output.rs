//! Tests of eenf's `output` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::output::*;
use std::path::Path;

#[test]
fn a_name_that_ends_in_a_slash_is_a_folder_not_made() {
    let dir = tempfile::tempdir().unwrap();
    let out = format!("{}/out/", dir.path().display());
    let Err(e) = AtomicFile::create(Path::new(&out)) else {
        panic!("{out} taken as a file");
    };
    assert!(
        e.to_string().contains("names a folder (it ends in /)"),
        "{e}"
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn written_whole_through_links_and_devices() {
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("real.txt");
    std::fs::write(&real, "old").unwrap();
    let link = dir.path().join("link.txt");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    write_atomic(&link, |w| Ok(w.write_all(b"new")?)).unwrap();
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
    // a failed write leaves the old file and no temporary
    assert!(write_atomic(&real, |_| Err(eenf::Error::Output("no".into()))).is_err());
    assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    write_atomic(Path::new("/dev/null"), |w| Ok(w.write_all(b"x")?)).unwrap();
    assert!(is_special_file(Path::new("/dev/null")));
}
