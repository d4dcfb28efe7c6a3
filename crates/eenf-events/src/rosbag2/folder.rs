//! A rosbag2 folder: `metadata.yaml` and the storage files it lists
//! (<https://github.com/ros2/rosbag2/tree/rolling/rosbag2_storage>, `relative_file_paths`),
//! or the storage files it holds, by name. A bag names its own files, never the reader's:
//! what the metadata lists must be regular files inside the folder, each listed once.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::error::{io_err, EventError, Result};

/// True when `dir` looks like a rosbag2 folder: it holds a storage file or `metadata.yaml`.
pub fn is_folder(dir: &Path) -> bool {
    dir.join("metadata.yaml").is_file() || storage_files(dir).is_ok_and(|f| !f.is_empty())
}

/// The largest `metadata.yaml` read: real ones are a few KB, a split bag of ten thousand
/// files some hundreds of KB.
pub const MAX_METADATA: u64 = 1 << 20;

/// The storage files of the rosbag2 folder `dir`, in the order the metadata lists them, else
/// by name. What the metadata lists must be regular files inside the folder, each listed once:
/// a bag names its own files, never the reader's (`/etc/passwd`, `../..`, a device).
pub fn storage_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let io = |e| io_err(dir, e);
    let yaml_path = dir.join("metadata.yaml");
    if let Ok(f) = std::fs::File::open(&yaml_path) {
        let mut yaml = Vec::new();
        f.take(MAX_METADATA + 1)
            .read_to_end(&mut yaml)
            .map_err(|e| io_err(&yaml_path, e))?;
        if yaml.len() as u64 > MAX_METADATA {
            return Err(unfit(
                dir,
                format!(
                    "its metadata.yaml is larger than {} KiB",
                    MAX_METADATA >> 10
                ),
            ));
        }
        let listed = listed_files(&String::from_utf8_lossy(&yaml));
        if !listed.is_empty() {
            return inside(dir, &listed);
        }
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(io)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            let name = name.strip_suffix(".zstd").unwrap_or(name);
            p.is_file() && (name.ends_with(".db3") || name.ends_with(".mcap"))
        })
        .collect();
    // split bags number their files: name_0, name_1, … name_10 in numeric order
    files.sort_by_key(|p| {
        let stem = p
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("")
            .to_string();
        let digits: String = stem
            .split('.')
            .next()
            .unwrap_or("")
            .rsplit('_')
            .next()
            .unwrap_or("")
            .chars()
            .filter(char::is_ascii_digit)
            .collect();
        (digits.parse::<u64>().unwrap_or(0), stem)
    });
    Ok(files)
}

fn unfit(dir: &Path, reason: String) -> EventError {
    EventError::Unfit {
        path: dir.to_path_buf(),
        reason,
    }
}

/// The files `listed` in the metadata of the bag `dir`, each a regular file inside `dir`
/// (symbolic links followed, and checked where they lead), each once.
fn inside(dir: &Path, listed: &[String]) -> Result<Vec<PathBuf>> {
    let root = std::fs::canonicalize(dir).map_err(|e| io_err(dir, e))?;
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::with_capacity(listed.len());
    for name in listed {
        let rel = Path::new(name);
        let outside = || {
            unfit(
                dir,
                format!(
                    "its metadata.yaml lists '{name}', which is not a file inside the bag's folder"
                ),
            )
        };
        if !rel
            .components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
        {
            return Err(outside());
        }
        // ROS 2 Foxy listed files under the bag folder's own name
        let mut file = dir.join(rel);
        if !file.exists() {
            if let Ok(rest) =
                rel.strip_prefix(root.file_name().map(Path::new).unwrap_or(Path::new("")))
            {
                file = dir.join(rest);
            }
        }
        let real = match std::fs::canonicalize(&file) {
            Ok(r) => r,
            Err(e) => {
                return Err(unfit(
                    dir,
                    format!("its metadata.yaml lists '{name}', which cannot be opened ({e})"),
                ))
            }
        };
        if !real.starts_with(&root) || !std::fs::metadata(&real).is_ok_and(|m| m.is_file()) {
            return Err(outside());
        }
        if !seen.insert(real) {
            return Err(unfit(
                dir,
                format!("its metadata.yaml lists '{name}' more than once"),
            ));
        }
        out.push(file);
    }
    Ok(out)
}

/// The items of `relative_file_paths:` in a rosbag2 `metadata.yaml`.
fn listed_files(yaml: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut lines = yaml
        .lines()
        .skip_while(|l| l.trim() != "relative_file_paths:");
    let Some(key) = lines.next() else {
        return out;
    };
    let indent = key.len() - key.trim_start().len();
    for l in lines {
        let t = l.trim_start();
        let this = l.len() - t.len();
        match t.strip_prefix("- ") {
            Some(item) if this >= indent => {
                out.push(item.trim().trim_matches(['"', '\'']).to_string())
            }
            _ => break,
        }
    }
    out
}

/// A reader of the rosbag2 folder `dir`: its topic `topic`, or its first topic of event
/// messages.
pub fn folder(dir: &Path, topic: Option<&str>) -> Result<Box<dyn crate::EventReader>> {
    let files = storage_files(dir)?;
    if files.is_empty() {
        return Err(EventError::UnknownFormat {
            path: dir.to_path_buf(),
            reason: "a folder without rosbag2 storage files (.db3, .mcap)".into(),
            supported: crate::SUPPORTED,
        });
    }
    super::start(dir, files, None, topic)
}
