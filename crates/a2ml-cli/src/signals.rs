//! Interruption: a run stopped by SIGINT, SIGTERM or SIGHUP removes the temporary files of
//! its outputs and exits with 128 + the signal's number (130, 143, 129).
//!
//! [`Temporaries`] creates each temporary file and commits them all while holding one lock,
//! which the signal thread takes before removing them: a temporary is either registered (and
//! removed) or already renamed, and the outputs of one run are renamed together or not at
//! all.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use a2ml_core::output::{OutputError, Staged};
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

use crate::error::CliError;

/// The temporary files of the outputs being written, shared with the signal thread.
#[derive(Debug, Clone, Default)]
pub struct Temporaries {
    paths: Arc<Mutex<Vec<PathBuf>>>,
}

impl Temporaries {
    /// Starts the thread that waits for SIGINT, SIGTERM and SIGHUP: on any of them it removes
    /// every registered temporary file and exits with 128 + the signal's number.
    ///
    /// # Errors
    /// [`CliError::Io`] when the signal handlers cannot be installed.
    pub fn install() -> Result<Self, CliError> {
        let mut signals = Signals::new([SIGINT, SIGTERM, SIGHUP])
            .map_err(|e| CliError::Io(format!("cannot handle signals: {e}")))?;
        let temporaries = Self::default();
        let paths = Arc::clone(&temporaries.paths);
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                // Held until the process exits, so no temporary is made or renamed after.
                let paths = paths.lock().unwrap_or_else(PoisonError::into_inner);
                for path in paths.iter() {
                    let _ = std::fs::remove_file(path);
                }
                std::process::exit(128 + signal);
            }
        });
        Ok(temporaries)
    }

    fn lock(&self) -> MutexGuard<'_, Vec<PathBuf>> {
        self.paths.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Creates the temporary file for `target` and registers it for removal on a signal.
    ///
    /// # Errors
    /// As [`Staged::create`].
    pub fn stage(&self, target: &Path) -> Result<Staged, OutputError> {
        let mut paths = self.lock();
        let staged = Staged::create(target)?;
        paths.push(staged.temporary().to_path_buf());
        Ok(staged)
    }

    /// Renames every staged file onto its target, in order, without a signal in between.
    ///
    /// # Errors
    /// The first rename that fails; the files after it are removed, those before it are
    /// already in place.
    pub fn commit_all(&self, staged: Vec<Staged>) -> Result<(), OutputError> {
        let mut paths = self.lock();
        // Only these files' entries go: other tasks of a batch may be staging theirs.
        paths.retain(|p| !staged.iter().any(|s| s.temporary() == p));
        staged.into_iter().try_for_each(Staged::commit)
    }
}
