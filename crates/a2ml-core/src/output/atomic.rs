//! Writing through a temporary file beside the target, renamed into place on success.
//!
//! A [`Staged`] output is a temporary file that is either renamed onto its target
//! ([`Staged::commit`]) or removed (dropped); several outputs are all staged first and then
//! committed together, so that a run failing on its second file leaves the first untouched.

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
    /// The Parquet writer failed.
    Parquet(String),
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
    pub(super) fn at(self, path: &Path) -> OutputError {
        let path = path.display().to_string();
        match self {
            Self::Io(e) => OutputError::Io { path, message: e.to_string() },
            Self::Mcap(message) => OutputError::Mcap { path, message },
            Self::Json(message) => OutputError::Json { path, message },
            Self::Parquet(message) => OutputError::Parquet { path, message },
        }
    }
}

/// What kind of thing is at an output path, when it is not a regular file that an output
/// may replace; `None` for a regular file or nothing at all.
///
/// # Errors
/// [`OutputError::Io`] when the path cannot be examined for another reason than not existing.
pub fn refused_kind(path: &Path) -> Result<Option<&'static str>, OutputError> {
    let metadata = match fs::symlink_metadata(path) {
        Ok(metadata) => metadata,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Failure::Io(e).at(path)),
    };
    let kind = metadata.file_type();
    Ok(if kind.is_file() {
        None
    } else if kind.is_dir() {
        Some("a folder")
    } else if kind.is_symlink() {
        Some("a symbolic link")
    } else {
        Some(special_kind(&kind))
    })
}

#[cfg(unix)]
fn special_kind(kind: &fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else if kind.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: &fs::FileType) -> &'static str {
    "not a regular file"
}

/// An output written to a temporary file beside its target, not yet in place. Dropping it
/// without [`Staged::commit`] removes the temporary file.
#[derive(Debug)]
pub struct Staged {
    temporary: PathBuf,
    target: PathBuf,
    file: Option<File>,
    committed: bool,
}

impl Staged {
    /// Creates the empty temporary file for `target`: `.<name>.tmp-<pid>` in the target's
    /// folder (the same file system, so the rename is atomic), with the permissions of the
    /// file it will replace, if any.
    ///
    /// # Errors
    /// [`OutputError::NotRegularFile`] when `target` is a folder, device, FIFO, socket or
    /// symbolic link (an output replaces only regular files); [`OutputError::Io`] when the
    /// temporary file cannot be made.
    pub fn create(target: &Path) -> Result<Self, OutputError> {
        if let Some(kind) = refused_kind(target)? {
            return Err(OutputError::NotRegularFile { path: target.display().to_string(), kind });
        }
        let temporary = temporary_path(target).map_err(|e| e.at(target))?;
        // create_new: never truncate a file this call did not make (and so may not remove).
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temporary)
            .map_err(|e| Failure::Io(e).at(target))?;
        let staged =
            Self { temporary, target: target.to_path_buf(), file: Some(file), committed: false };
        if let Ok(old) = fs::metadata(target) {
            fs::set_permissions(&staged.temporary, old.permissions())
                .map_err(|e| Failure::Io(e).at(target))?;
        }
        Ok(staged)
    }

    /// The temporary file's path.
    pub fn temporary(&self) -> &Path {
        &self.temporary
    }

    /// The path it will be renamed to.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Runs `write` on the temporary file and syncs it to disk; the file is closed after.
    pub(super) fn fill(
        &mut self,
        write: impl FnOnce(&mut BufWriter<File>) -> Result<(), Failure>,
    ) -> Result<(), OutputError> {
        let file = self.file.take().ok_or_else(|| {
            let e = io::Error::other("the temporary file was already written");
            Failure::Io(e).at(&self.target)
        })?;
        let fill = || -> Result<(), Failure> {
            let mut out = BufWriter::new(file);
            write(&mut out)?;
            let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
            file.sync_all()?;
            Ok(())
        };
        fill().map_err(|e| e.at(&self.target))
    }

    /// Renames the temporary file onto the target.
    ///
    /// # Errors
    /// [`OutputError::Io`] when the rename fails; the temporary file is then removed and the
    /// target left as it was.
    pub fn commit(mut self) -> Result<(), OutputError> {
        if self.file.is_some() {
            let e = io::Error::other("the temporary file was never written");
            return Err(Failure::Io(e).at(&self.target));
        }
        fs::rename(&self.temporary, &self.target).map_err(|e| Failure::Io(e).at(&self.target))?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            self.file = None;
            // Best effort: whatever made the output fail is the error worth reporting.
            let _ = fs::remove_file(&self.temporary);
        }
    }
}

/// Runs `write` on a new temporary file in the target's folder, then renames it to `path`;
/// on any failure the temporary file is removed and `path` is left as it was.
pub(super) fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), Failure>,
) -> Result<(), OutputError> {
    let mut staged = Staged::create(path)?;
    staged.fill(write)?;
    staged.commit()
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
