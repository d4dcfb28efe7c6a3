//! An upload streamed to a file the server names, under a size cap, hashed as it arrives.

use std::path::{Path, PathBuf};

use axum::extract::multipart::Field;
use sha2::{Digest, Sha256};
use tokio::io::AsyncWriteExt;

/// Extensions an upload keeps (lower case), so that the library reads it as what it is: a
/// trace by .csv/.json, a video by its container, sound through ffmpeg. Anything else is
/// stored without one (event files are recognised by their content).
const KEPT_EXTENSIONS: [&str; 41] = [
    "csv", "json", "wav", "flac", "mp3", "ogg", "oga", "opus", "m4a", "aac", "wma", "aif", "aiff",
    "caf", "amr", "y4m", "mp4", "mov", "mkv", "webm", "avi", "m4v", "mts", "m2ts", "3gp", "mpg",
    "aedat", "aedat4", "raw", "dat", "evt", "txt", "h5", "hdf5", "bag", "mcap", "db3", "es", "npy",
    "bin", "csv.gz",
];

/// The extension the stored file gets: one from [`KEPT_EXTENSIONS`] that the browser's name
/// ends with, never a piece of that name itself.
pub(crate) fn extension_for(client_name: &str) -> Option<&'static str> {
    let lower = client_name.to_ascii_lowercase();
    KEPT_EXTENSIONS
        .iter()
        .copied()
        .filter(|e| lower.ends_with(&format!(".{e}")))
        .max_by_key(|e| e.len())
}

/// The name shown for an upload: the browser's name without its folders, control characters
/// or excess length (it is only ever displayed, escaped).
pub(crate) fn display_name(client_name: Option<&str>) -> String {
    let base = client_name
        .unwrap_or("")
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or("");
    let clean: String = base.chars().filter(|c| !c.is_control()).take(200).collect();
    if clean.trim().is_empty() {
        "upload".to_string()
    } else {
        clean
    }
}

/// What was received.
pub(crate) struct Received {
    pub path: PathBuf,
    pub size: u64,
    pub sha256: String,
}

/// Why an upload was not taken.
#[derive(Debug)]
pub(crate) enum UploadError {
    /// More than the cap.
    TooLarge(u64),
    /// The connection or the body broke off, or the file could not be written.
    Broken(String),
}

/// Streams `field` into `dir/<id>[.ext]`, stopping (and removing the file) past `cap` bytes.
pub(crate) async fn receive(
    mut field: Field<'_>,
    dir: &Path,
    id: u64,
    ext: Option<&str>,
    cap: u64,
) -> Result<Received, UploadError> {
    let path = dir.join(match ext {
        Some(e) => format!("{id}.{e}"),
        None => id.to_string(),
    });
    let result = async {
        let mut file = tokio::fs::File::create_new(&path)
            .await
            .map_err(|e| UploadError::Broken(format!("cannot store the upload: {e}")))?;
        let (mut size, mut hash) = (0u64, Sha256::new());
        while let Some(chunk) = field
            .chunk()
            .await
            .map_err(|e| UploadError::Broken(format!("the upload broke off: {e}")))?
        {
            size += chunk.len() as u64;
            if size > cap {
                return Err(UploadError::TooLarge(cap));
            }
            hash.update(&chunk);
            file.write_all(&chunk)
                .await
                .map_err(|e| UploadError::Broken(format!("cannot store the upload: {e}")))?;
        }
        file.flush()
            .await
            .map_err(|e| UploadError::Broken(format!("cannot store the upload: {e}")))?;
        let sha256 = hash.finalize().iter().map(|b| format!("{b:02x}")).collect();
        Ok((size, sha256))
    }
    .await;
    match result {
        Ok((size, sha256)) => Ok(Received { path, size, sha256 }),
        Err(e) => {
            let _ = tokio::fs::remove_file(&path).await;
            Err(e)
        }
    }
}
