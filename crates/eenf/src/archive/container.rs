//! An archive's container: plain text, gzip, or the tables of a zip or 7z archive, read as
//! streams, line by line with a bound on a line's length.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use crate::error::{error, fail, Context, Error, Result};

use super::MAX_LINE;

/// What an archive's container is, from its first bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Container {
    Zip,
    SevenZip,
    Gzip,
    Text,
}

pub(super) fn container_of(head: &[u8]) -> Container {
    if head.starts_with(b"PK\x03\x04") {
        Container::Zip
    } else if head.starts_with(b"7z\xBC\xAF\x27\x1C") {
        Container::SevenZip
    } else if head.starts_with(b"\x1f\x8b") {
        Container::Gzip
    } else {
        Container::Text
    }
}

/// Whether a member of a zip or 7z archive is a table to read.
pub(super) fn is_table(name: &str) -> bool {
    let n = name.to_ascii_lowercase();
    [".csv", ".txt", ".tsv", ".dat"]
        .iter()
        .any(|e| n.ends_with(e))
}

pub(super) type MemberFn<'a> = dyn FnMut(Option<&str>, &mut dyn BufRead) -> Result<()> + 'a;

/// Calls `each` with every table `path` holds, in name order for zips and in stored order
/// for 7z. Damage stops the reading with a warning (returned); what was read is kept.
pub(super) fn for_each_member(path: &Path, each: &mut MemberFn<'_>) -> Result<Vec<String>> {
    let name = path.display();
    let open = || File::open(path).with_context(|| format!("{name}"));
    if path.is_dir() {
        fail!(Archive, "{name}: a folder, not a grid archive");
    }
    let mut head = [0u8; 6];
    let n = open()?.read(&mut head).with_context(|| format!("{name}"))?;
    let mut warnings = Vec::new();
    match container_of(&head[..n]) {
        // an operator's JSON answer, read as the table it holds
        Container::Text if super::operator_json::looks_like_json(&head[..n]) => {
            let (kind, table) = super::operator_json::to_table(path)?;
            each(Some(kind.describe()), &mut std::io::Cursor::new(table))?;
        }
        Container::Text => each(None, &mut BufReader::new(open()?))?,
        Container::Gzip => {
            let gz = flate2::read::MultiGzDecoder::new(BufReader::new(open()?));
            each(None, &mut BufReader::new(gz))?;
        }
        Container::Zip => {
            let mut zip = match zip::ZipArchive::new(BufReader::new(open()?)) {
                Ok(z) => z,
                // no directory at the end (a download cut short): the members in order
                Err(e) => return zip_in_order(path, each, e),
            };
            let mut names: Vec<String> = zip
                .file_names()
                .filter_map(|n| n.ok().map(|n| n.into_owned()))
                .collect();
            names.sort();
            let skipped: Vec<&String> = names
                .iter()
                .filter(|n| !is_table(n) && !n.ends_with('/'))
                .collect();
            if !skipped.is_empty() {
                warnings.push(format!(
                    "{name}: skipped {} member(s) that are not tables (e.g. {})",
                    skipped.len(),
                    skipped[0]
                ));
            }
            let tables: Vec<String> = names.iter().filter(|n| is_table(n)).cloned().collect();
            if tables.is_empty() {
                fail!(
                    Archive,
                    "{name}: a zip archive with no CSV or text table in it"
                );
            }
            for m in &tables {
                let entry = match zip.by_name(m) {
                    Ok(e) => e,
                    Err(e) => {
                        warnings.push(format!(
                            "{name}: member {m} is damaged ({e}); stopped there, the members before it are kept"
                        ));
                        break;
                    }
                };
                each(Some(m), &mut BufReader::new(entry))?;
            }
        }
        Container::SevenZip => {
            let mut reader = sevenz_rust2::ArchiveReader::new(
                BufReader::new(open()?),
                sevenz_rust2::Password::empty(),
            )
            .map_err(|e| error!(Archive, "{name}: not a readable 7z archive: {e}"))?;
            let mut failure: Option<Error> = None;
            let mut tables = 0usize;
            let walked = reader.for_each_entries(|entry, r| {
                if entry.is_directory || !is_table(&entry.name) {
                    return Ok(true);
                }
                tables += 1;
                match each(Some(&entry.name), &mut BufReader::new(r)) {
                    Ok(()) => Ok(true),
                    Err(e) => {
                        failure = Some(e);
                        Ok(false)
                    }
                }
            });
            if let Some(e) = failure {
                return Err(e);
            }
            if let Err(e) = walked {
                warnings.push(format!(
                    "{name}: damaged ({e}); stopped there, the members before it are kept"
                ));
            }
            if tables == 0 {
                fail!(
                    Archive,
                    "{name}: a 7z archive with no CSV or text table in it"
                );
            }
        }
    }
    Ok(warnings)
}

/// The members of a zip whose central directory cannot be read, in the order they are stored,
/// up to the damage (a cut-short download keeps its first days).
pub(super) fn zip_in_order(
    path: &Path,
    each: &mut MemberFn<'_>,
    why: zip::result::ZipError,
) -> Result<Vec<String>> {
    let name = path.display();
    let mut r = BufReader::new(File::open(path).with_context(|| format!("{name}"))?);
    let mut tables = 0usize;
    let mut warnings = Vec::new();
    loop {
        match zip::read::read_zipfile_from_stream(&mut r) {
            Ok(Some(entry)) => {
                let member = entry.name().map(|n| n.into_owned()).unwrap_or_default();
                if is_table(&member) {
                    tables += 1;
                    each(Some(&member), &mut BufReader::new(entry))?;
                }
            }
            Ok(None) => break,
            Err(e) => {
                if tables > 0 {
                    warnings.push(format!(
                        "{name}: a damaged zip archive ({why}; then {e}): the members before the damage are kept"
                    ));
                }
                break;
            }
        }
    }
    if tables == 0 {
        fail!(
            Archive,
            "{name}: not a readable zip archive ({why}), and no whole table at its start"
        );
    }
    Ok(warnings)
}

/// Reads one line (without its end) into `buf`: the bytes read, 0 at the end. A line longer
/// than [`MAX_LINE`] is an error: the file is no table.
pub(super) fn read_line(r: &mut dyn BufRead, buf: &mut Vec<u8>) -> Result<usize> {
    let mut total = 0;
    loop {
        let chunk = r.fill_buf()?;
        if chunk.is_empty() {
            return Ok(total);
        }
        let (take, done) = match chunk.iter().position(|&b| b == b'\n') {
            Some(i) => (i + 1, true),
            None => (chunk.len(), false),
        };
        buf.extend_from_slice(&chunk[..take]);
        r.consume(take);
        total += take;
        if buf.len() > MAX_LINE {
            fail!(
                Archive,
                "a line longer than {} KiB: not a table",
                MAX_LINE >> 10
            );
        }
        if done {
            while buf.last().is_some_and(|&b| b == b'\n' || b == b'\r') {
                buf.pop();
            }
            return Ok(total);
        }
    }
}

/// The first `n` lines that hold something (not blank, not `#` comments), as text; a UTF-8
/// byte order mark is dropped.
pub(super) fn first_lines(r: &mut dyn BufRead, n: usize) -> Result<Vec<String>> {
    let mut out = Vec::new();
    let mut buf = Vec::new();
    while out.len() < n {
        buf.clear();
        if read_line(r, &mut buf)? == 0 {
            break;
        }
        if out.is_empty() && buf.starts_with(b"\xEF\xBB\xBF") {
            buf.drain(..3);
        }
        if buf.starts_with(b"\xFF\xFE") || buf.starts_with(b"\xFE\xFF") {
            fail!(Archive, "UTF-16 text: save it as UTF-8");
        }
        let line = String::from_utf8_lossy(&buf).into_owned();
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        out.push(line);
    }
    Ok(out)
}
