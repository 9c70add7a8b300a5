//! Writing through a temporary file beside the target, renamed into place on success.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};

use super::OutputError;

/// What went wrong inside a writer, before the path is attached.
#[derive(Debug)]
pub(super) enum Failure {
    /// The file system refused.
    Io(io::Error),
    /// The MCAP writer failed.
    Mcap(String),
    /// JSON encoding failed.
    Json(String),
}

impl From<io::Error> for Failure {
    fn from(e: io::Error) -> Self {
        Self::Io(e)
    }
}

impl From<serde_json::Error> for Failure {
    fn from(e: serde_json::Error) -> Self {
        match e.io_error_kind() {
            Some(kind) => Self::Io(io::Error::new(kind, e)),
            None => Self::Json(e.to_string()),
        }
    }
}

impl Failure {
    /// The public error, naming the target path.
    fn at(self, path: &Path) -> OutputError {
        let path = path.display().to_string();
        match self {
            Self::Io(e) => OutputError::Io { path, message: e.to_string() },
            Self::Mcap(message) => OutputError::Mcap { path, message },
            Self::Json(message) => OutputError::Json { path, message },
        }
    }
}

/// Runs `write` on a new temporary file in the target's folder, then renames it to `path`;
/// on any failure the temporary file is removed and `path` is left as it was.
pub(super) fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), Failure>,
) -> Result<(), OutputError> {
    let tmp = temporary_path(path).map_err(|e| e.at(path))?;
    // create_new: never truncate a file this call did not make (and so may not remove).
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&tmp)
        .map_err(|e| Failure::Io(e).at(path))?;
    let result = fill_and_rename(file, &tmp, path, write);
    if result.is_err() {
        // Best effort: the write already failed, and that is the error worth reporting.
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(|e| e.at(path))
}

fn fill_and_rename(
    file: File,
    tmp: &Path,
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), Failure>,
) -> Result<(), Failure> {
    let mut out = BufWriter::new(file);
    write(&mut out)?;
    let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
    file.sync_all()?;
    drop(file);
    fs::rename(tmp, path)?;
    Ok(())
}

/// `.<name>.tmp-<pid>` in the target's folder: the same file system, so the rename is atomic,
/// and hidden from a plain `ls`.
fn temporary_path(path: &Path) -> Result<PathBuf, Failure> {
    let name = path.file_name().ok_or_else(|| {
        Failure::Io(io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))
    })?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(name);
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    Ok(path.with_file_name(tmp_name))
}
