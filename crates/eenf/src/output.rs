//! Output files, written whole or not at all: every file eenf writes goes through
//! [`AtomicFile`]. A regular target gets a temporary file beside it, renamed over it when
//! complete; a symlink's real file is the target (the link stays); a device, a FIFO or `-`
//! (stdout) is written into (renaming over `/dev/null` would replace the device), from a
//! temporary copy so that it too gets the whole output or nothing. Missing parent folders are
//! created. Temporary files (and folders being built) are removed on errors and, through
//! [`remove_in_progress`], when the program is interrupted.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{fail, Context, Result};
use tempfile::NamedTempFile;

pub use eenf_core::cleanup::{
    forget_in_progress, register_in_progress, remove_in_progress, InProgress,
};

/// True when `path` names stdout (`-`).
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// The folder that holds `path` (`.` for a bare name).
pub fn folder_of(path: &Path) -> &Path {
    path.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// Creates the missing parent folders of the output `path`.
pub fn create_parent(path: &Path) -> Result<()> {
    let d = folder_of(path);
    if d.exists() {
        return Ok(());
    }
    std::fs::create_dir_all(d).with_context(|| format!("{}: cannot create the folder", d.display()))
}

/// True when `path` exists and is not a regular file or folder (a device, a FIFO).
pub fn is_special_file(path: &Path) -> bool {
    std::fs::metadata(path)
        .map(|m| !m.is_file() && !m.is_dir())
        .unwrap_or(false)
}

/// A file being written under a temporary name; dropped unfinished, it leaves nothing.
pub struct AtomicFile {
    target: PathBuf,
    tmp: NamedTempFile,
    special: bool,
    _in_progress: InProgress,
}

impl AtomicFile {
    /// Starts writing `path`.
    pub fn create(path: &Path) -> Result<Self> {
        Self::with_suffix(path, ".tmp")
    }

    /// Starts writing `path` through a temporary file that keeps its extension, for writers
    /// that pick the format from the name (the plotting backends).
    pub fn keeping_extension(path: &Path) -> Result<Self> {
        let ext = path.extension().unwrap_or_default().to_string_lossy();
        Self::with_suffix(path, &format!(".tmp.{ext}"))
    }

    fn with_suffix(path: &Path, suffix: &str) -> Result<Self> {
        // a link is followed: the file it names is replaced, the link itself stays
        let target = match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => {
                std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
            }
            _ => path.to_path_buf(),
        };
        if target.is_dir() {
            // an OS error of its kind, so that each front end can say what it is
            return Err(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                format!("{}: is a folder, not a file", path.display()),
            )
            .into());
        }
        if path.as_os_str().to_string_lossy().ends_with('/') {
            fail!(
                Output,
                "{}: names a folder (it ends in /), not a file: give the file's name, e.g. {}out{}",
                path.display(),
                path.display(),
                match suffix.rsplit_once('.') {
                    Some((_, ext)) if !ext.is_empty() && ext != "tmp" => format!(".{ext}"),
                    _ => ".csv".into(),
                }
            );
        }
        let special = is_stdout(path) || is_special_file(&target);
        if !special {
            create_parent(&target)?;
        }
        let dir = if special {
            std::env::temp_dir()
        } else {
            folder_of(&target).to_path_buf()
        };
        let name = target.file_name().unwrap_or_default().to_string_lossy();
        let prefix = format!(".{name}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(suffix);
        #[cfg(unix)]
        builder.permissions(permissions_for(&target));
        let tmp = builder
            .tempfile_in(&dir)
            .with_context(|| format!("{}: cannot create a temporary file", path.display()))?;
        Ok(AtomicFile {
            target,
            _in_progress: InProgress::new(tmp.path()),
            tmp,
            special,
        })
    }

    /// The temporary file's path, for writers that open it by name.
    pub fn path(&self) -> &Path {
        self.tmp.path()
    }

    /// A handle on the temporary file, for writers that own their output.
    pub fn file(&self) -> Result<File> {
        self.tmp
            .as_file()
            .try_clone()
            .with_context(|| format!("{}", self.target.display()))
    }

    /// Puts the finished file in place.
    pub fn commit(self) -> Result<()> {
        let target = self.target;
        let what = || {
            format!(
                "{}: cannot move the finished file into place",
                target.display()
            )
        };
        if self.special {
            let mut src = self.tmp.reopen().with_context(what)?;
            if is_stdout(&target) {
                let mut out = std::io::stdout().lock();
                // the io::Error stays in the chain: a closed pipe ends the program quietly
                std::io::copy(&mut src, &mut out).context("stdout")?;
                out.flush().context("stdout")?;
                return Ok(());
            }
            let mut dst = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .with_context(what)?;
            std::io::copy(&mut src, &mut dst).with_context(what)?;
            return Ok(());
        }
        self.tmp.as_file().sync_all().with_context(what)?;
        self.tmp
            .persist(&target)
            .map_err(|e| e.error)
            .with_context(what)?;
        Ok(())
    }
}

/// New files get the usual 0644; a replaced file keeps its own permissions.
#[cfg(unix)]
fn permissions_for(target: &Path) -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    match std::fs::metadata(target) {
        Ok(m) if m.is_file() => m.permissions(),
        _ => std::fs::Permissions::from_mode(0o644),
    }
}

/// Writes `path` whole or not at all through `write`.
pub fn write_atomic(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let out = AtomicFile::create(path)?;
    let res = (|| -> Result<()> {
        let mut w = BufWriter::new(out.file()?);
        write(&mut w)?;
        w.flush()?;
        Ok(())
    })();
    match res {
        Ok(()) => out.commit(),
        Err(e) => Err(e.context(format!("{}: cannot write", path.display()))),
    }
}

/// Writes the event file `path` in `format` whole or not at all: `write` feeds the writer.
pub fn write_events(
    path: &Path,
    format: eenf_events::writers::OutputFormat,
    width: u16,
    height: u16,
    write: impl FnOnce(&mut dyn eenf_events::writers::EventWriter) -> Result<()>,
) -> Result<u64> {
    let out = AtomicFile::create(path)?;
    let mut writer =
        eenf_events::writers::writer(Box::new(out.file()?), path, format, width, height)?;
    write(writer.as_mut())?;
    let n = writer.finish()?;
    out.commit()?;
    Ok(n)
}

/// NAME.ext → NAME.<suffix>
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.{suffix}"))
}
