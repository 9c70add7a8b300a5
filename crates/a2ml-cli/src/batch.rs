//! `a2ml plan` over many task files: the files named, found in folders or matched by quoted
//! patterns ([`task_files`]), planned `--jobs` at a time on a rayon pool, each exactly as
//! alone ([`crate::commands::plan::Planning`]), one line each in the order given, then the
//! count; the exit status is the worst of the tasks'.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Instant;

use rayon::prelude::*;

use crate::commands::plan::{self, PlanArgs, Planning};
use crate::error::CliError;
use crate::output::{self, num};
use crate::signals::Temporaries;

/// The task files of `inputs` in order: a file as given, a folder's `*.a2ml` files sorted by
/// name, a pattern's matches sorted by name; each file once.
///
/// # Errors
/// [`CliError::Input`] for a folder without task files, a pattern that is not valid or that
/// matches nothing; [`CliError::Io`] for a folder that cannot be listed.
pub fn task_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, CliError> {
    let mut files = Vec::new();
    for input in inputs {
        let found = if input.is_dir() {
            folder_tasks(input)?
        } else if !input.exists() && is_pattern(input) {
            pattern_tasks(input)?
        } else {
            vec![input.clone()]
        };
        for file in found {
            if !files.contains(&file) {
                files.push(file);
            }
        }
    }
    Ok(files)
}

/// Whether a path that does not exist is meant as a pattern.
fn is_pattern(path: &Path) -> bool {
    path.to_string_lossy().contains(['*', '?', '['])
}

fn folder_tasks(folder: &Path) -> Result<Vec<PathBuf>, CliError> {
    let entries = std::fs::read_dir(folder)
        .map_err(|e| CliError::Io(format!("cannot list {}: {e}", folder.display())))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|entry| entry.path())
        .filter(|path| path.is_file() && path.extension().is_some_and(|e| e == "a2ml"))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(CliError::Input(format!("{} holds no .a2ml file", folder.display())));
    }
    Ok(files)
}

fn pattern_tasks(pattern: &Path) -> Result<Vec<PathBuf>, CliError> {
    let text = pattern.to_string_lossy();
    let matches = glob::glob(&text)
        .map_err(|e| CliError::Input(format!("{text} is not a valid pattern: {e}")))?;
    let mut files: Vec<PathBuf> = matches.filter_map(Result::ok).filter(|p| p.is_file()).collect();
    files.sort();
    if files.is_empty() {
        return Err(CliError::Input(format!("no file matches {text}")));
    }
    Ok(files)
}

/// How bad a task's failure is, for the batch's exit status: an unreadable or unwritable
/// file, then invalid input, then a failed solve, then a missed goal (whose files exist).
fn severity(error: &CliError) -> u8 {
    match error {
        CliError::Io(_) => 4,
        CliError::Input(_) => 3,
        CliError::Planning(_) => 2,
        CliError::Missed(_) => 1,
    }
}

/// What became of one task: its line, and its failure if any.
struct Outcome {
    line: String,
    failure: Option<CliError>,
}

/// Plans every file of `files` on a pool of `--jobs` threads and reports each in order.
///
/// # Errors
/// Before planning, [`CliError::Input`] when two tasks would write one file; after, the
/// worst task failure, with the count of tasks that failed.
pub fn run(args: &PlanArgs, files: &[PathBuf], temporaries: &Temporaries) -> Result<(), CliError> {
    check_distinct_outputs(args, files)?;
    let jobs = args.jobs.map_or_else(rayon::current_num_threads, std::num::NonZeroUsize::get);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| CliError::Io(format!("cannot start {jobs} planning threads: {e}")))?;
    let started = Instant::now();
    let (sender, receiver) = mpsc::channel();
    let mut failures: Vec<CliError> = Vec::new();
    let mut printed = Ok(());
    std::thread::scope(|scope| {
        scope.spawn(|| {
            pool.install(|| {
                files.par_iter().enumerate().for_each_with(sender, |sender, (index, file)| {
                    // The receiver lives until every task is done.
                    let _ = sender.send((index, plan_task(args, file, files, temporaries)));
                });
            });
        });
        // Lines in the order given, each as soon as those before it are done.
        let mut done = BTreeMap::new();
        let mut next = 0;
        for (index, outcome) in receiver {
            done.insert(index, outcome);
            while let Some(outcome) = done.remove(&next) {
                let Outcome { line, failure } = outcome;
                if printed.is_ok() {
                    printed = output::print(&line);
                }
                failures.extend(failure);
                next += 1;
            }
        }
    });
    printed?;
    finish(files.len(), &failures, started.elapsed().as_secs_f64())
}

/// Refuses a batch in which two tasks would write the same file (an output without `{stem}`,
/// or two task files of one stem).
///
/// # Errors
/// [`CliError::Input`] naming the file and both tasks.
fn check_distinct_outputs(args: &PlanArgs, files: &[PathBuf]) -> Result<(), CliError> {
    let mut writers: HashMap<PathBuf, &Path> = HashMap::new();
    for file in files {
        for (_, path) in plan::outputs(args, file) {
            if let Some(other) = writers.insert(path.clone(), file) {
                return Err(CliError::Input(format!(
                    "{} and {} would both write {}: put {} in the output's name",
                    other.display(),
                    file.display(),
                    path.display(),
                    plan::STEM
                )));
            }
        }
    }
    Ok(())
}

/// Plans one task of the batch as `a2ml plan FILE` would, and sums it up in one line.
fn plan_task(
    args: &PlanArgs,
    file: &Path,
    batch: &[PathBuf],
    temporaries: &Temporaries,
) -> Outcome {
    let started = Instant::now();
    let outputs = plan::outputs(args, file);
    let planned = plan::check_outputs(&outputs)
        .and_then(|()| Planning::load(args, file, &outputs, batch))
        .and_then(|planning| {
            let plan = planning.plan(&mut |_| {})?;
            planning.write(temporaries, &outputs, &plan)?;
            Ok(plan)
        });
    let seconds = num(started.elapsed().as_secs_f64(), 2);
    match planned {
        Ok(plan) => {
            for warning in &plan.warnings {
                output::warn(&format!("{}: {warning}", file.display()));
            }
            let clearance = plan
                .segments
                .iter()
                .filter_map(|s| s.clearance.as_ref())
                .map(|c| c.distance)
                .reduce(f64::min)
                .map_or_else(String::new, |d| format!(", clearance {} mm", num(d * 1e3, 1)));
            let facts = format!(
                "{}, {} s{clearance}, planned in {seconds} s",
                output::count(plan.segments.len(), "segment"),
                num(plan.trajectory.duration(), 3),
            );
            match plan::verdict(&plan) {
                Ok(()) => Outcome {
                    line: format!("ok      {}  {facts}\n", file.display()),
                    failure: None,
                },
                Err(e) => Outcome {
                    line: format!("missed  {}  {facts}: {e}\n", file.display()),
                    failure: Some(e),
                },
            }
        }
        Err(e) => {
            // Solver messages already begin with the file.
            let message = e.to_string();
            let prefix = format!("{}: ", file.display());
            let message = message.strip_prefix(&prefix).unwrap_or(&message);
            Outcome {
                line: format!("failed  {}  exit {}: {message}\n", file.display(), code(&e)),
                failure: Some(e),
            }
        }
    }
}

/// The exit code a task's failure would have alone.
fn code(error: &CliError) -> u8 {
    match error {
        CliError::Io(_) => 1,
        CliError::Input(_) => 2,
        CliError::Missed(_) => 3,
        CliError::Planning(_) => 4,
    }
}

/// The final count, and the batch's outcome: the worst failure's kind.
///
/// # Errors
/// The worst of `failures`, its message the count.
fn finish(tasks: usize, failures: &[CliError], seconds: f64) -> Result<(), CliError> {
    let missed = failures.iter().filter(|e| matches!(e, CliError::Missed(_))).count();
    let failed = failures.len() - missed;
    output::print(&format!(
        "\n{}: {} ok, {missed} missed, {failed} failed, in {} s\n",
        output::count(tasks, "task"),
        tasks - failures.len(),
        num(seconds, 2)
    ))?;
    let Some(worst) = failures.iter().max_by_key(|e| severity(e)) else { return Ok(()) };
    let message = format!(
        "{} of {} did not plan as asked ({missed} missed, {failed} failed)",
        failures.len(),
        output::count(tasks, "task")
    );
    Err(match worst {
        CliError::Io(_) => CliError::Io(message),
        CliError::Input(_) => CliError::Input(message),
        CliError::Planning(_) => CliError::Planning(message),
        CliError::Missed(_) => CliError::Missed(message),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_worst_failure_decides_the_exit_code() {
        let missed = CliError::Missed("m".into());
        let planning = CliError::Planning("p".into());
        let input = CliError::Input("i".into());
        assert_eq!(finish(3, &[], 0.0), Ok(()));
        assert!(matches!(finish(3, std::slice::from_ref(&missed), 0.0), Err(CliError::Missed(_))));
        let both = [missed.clone(), planning.clone()];
        assert!(matches!(finish(3, &both, 0.0), Err(CliError::Planning(_))));
        let all = [missed, input, planning];
        assert_eq!(
            finish(4, &all, 0.0),
            Err(CliError::Input("3 of 4 tasks did not plan as asked (1 missed, 2 failed)".into()))
        );
    }

    #[test]
    fn patterns_are_paths_with_wildcards() {
        assert!(is_pattern(Path::new("tasks/*.a2ml")));
        assert!(is_pattern(Path::new("tasks/reach_?.a2ml")));
        assert!(!is_pattern(Path::new("tasks/reach.a2ml")));
    }
}
