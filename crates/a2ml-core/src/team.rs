//! Helper threads for a batch of independent rows: the Python wheel's batched kinematics
//! (`Robot.fk_many` and its kin, `crates/a2ml-py/src/batch.rs`) share a large batch with them.
//!
//! A thread that sleeps takes tens of microseconds to wake on the virtual machines we measure
//! on (34–55 µs for a thread of rayon's pool, against 48 µs for a whole 1,000-row `fk_many`),
//! so a batch that waits for its helper, as a `rayon` scope does, often ends later than one
//! thread alone would. Here the calling thread never waits for a helper that has not started:
//! it posts its work, does it itself, and when nothing is left waits only for the helpers
//! already inside, each at most one piece from its end. A helper keeps watching for the next
//! batch for [`LINGER`] after its last one, as OpenMP runtimes and BLAS pools do between
//! parallel regions, so a loop of batched calls finds it awake; then it dozes, then sleeps
//! (see `watch`).
//!
//! The work is one closure that every thread runs at once; it shares itself out (each thread
//! takes the next piece from a common queue) and returns when no piece is left. Which thread
//! runs a piece changes no result.

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering::SeqCst};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::{self, Thread};
use std::time::{Duration, Instant};

/// How long a helper spins for the next batch after its last one before it dozes: longer
/// than the Python work between two batched calls of a typical loop (a millisecond or two),
/// short enough that an idle process gives its cores back at once to a person's eye.
pub const LINGER: Duration = Duration::from_millis(5);

/// How often a dozing helper looks for work, between [`LINGER`] and [`IDLE`] after its last.
pub const DOZE: Duration = Duration::from_micros(500);

/// How long after its last work a helper dozes before it sleeps for good (until woken).
pub const IDLE: Duration = Duration::from_secs(1);

/// How long a helper waits in each manner: [`LINGER`], [`DOZE`] and [`IDLE`] for the process's
/// team, shorter in the tests.
#[derive(Debug, Clone, Copy)]
struct Patience {
    linger: Duration,
    doze: Duration,
    idle: Duration,
}

/// Helpers at most, whatever the number of cores: a batch of a thousand rows has 16 pieces.
const MOST_HELPERS: usize = 7;

/// The work of one batch, as every thread runs it.
type Work<'a> = &'a (dyn Fn() + Sync);

/// What the caller and its helpers share.
struct Shared {
    /// The address of the posted [`Work`] (on the caller's stack), 0 when none is posted.
    posted: AtomicUsize,
    /// Counts the posts, so that a helper enters each one once.
    generation: AtomicUsize,
    /// Helpers inside the posted work: the caller waits for them to leave before its stack
    /// frame (and the work) goes away.
    inside: AtomicUsize,
    /// One caller posts at a time; another batch meanwhile runs on its own thread alone.
    posting: AtomicBool,
    /// A helper's panic, which its caller resumes.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
}

/// A helper thread and whether it sleeps (parked, to be unparked by the next post).
struct Helper {
    thread: Thread,
    asleep: Arc<AtomicBool>,
}

/// The helpers of the process (the extension's threads, like rayon's global pool).
pub struct Team {
    shared: Arc<Shared>,
    helpers: Vec<Helper>,
}

/// The environment variable that sets how many threads a batch may use, its caller included:
/// `1` runs every batch on its caller alone (no helper thread is started); unset, empty or not
/// a positive number, the cores the process may use, at most `MOST_HELPERS + 1`. For many
/// processes on one machine (a Dask or Ray worker per core), `1` keeps the helpers from
/// spinning on cores the other processes need.
pub const THREADS_VARIABLE: &str = "A2ML_BATCH_THREADS";

/// The helpers a team takes, from [`THREADS_VARIABLE`]'s value and the number of cores.
fn helpers_for(setting: Option<&str>, cores: usize) -> usize {
    let threads = setting
        .and_then(|text| text.trim().parse::<usize>().ok())
        .filter(|&threads| threads > 0)
        .unwrap_or(cores);
    threads.saturating_sub(1).min(MOST_HELPERS)
}

/// The process's team, its threads started at the first large batch, as many as
/// [`THREADS_VARIABLE`] says. A helper that cannot be started is left out.
///
/// A process forked from one with a team has none of its threads (a fork copies only the
/// forking thread), and a helper that was inside a batch at the fork would seem inside for
/// ever: the child, told apart by its process id, makes a team of its own (the parent's is
/// left as it was, a few bytes).
pub fn team() -> &'static Team {
    static TEAM: Mutex<Option<(u32, &'static Team)>> = Mutex::new(None);
    let pid = std::process::id();
    let mut current = TEAM.lock().unwrap_or_else(PoisonError::into_inner);
    match *current {
        Some((owner, team)) if owner == pid => team,
        _ => {
            let cores = thread::available_parallelism().map_or(1, usize::from);
            let setting = std::env::var(THREADS_VARIABLE).ok();
            let patience = Patience { linger: LINGER, doze: DOZE, idle: IDLE };
            let team: &'static Team =
                Box::leak(Box::new(Team::new(helpers_for(setting.as_deref(), cores), patience)));
            *current = Some((pid, team));
            team
        }
    }
}

impl Team {
    /// A team of `helpers` threads.
    fn new(helpers: usize, patience: Patience) -> Self {
        let shared = Arc::new(Shared {
            posted: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            inside: AtomicUsize::new(0),
            posting: AtomicBool::new(false),
            panic: Mutex::new(None),
        });
        let helpers = (0..helpers)
            .filter_map(|k| {
                let asleep = Arc::new(AtomicBool::new(false));
                let (shared, flag) = (Arc::clone(&shared), Arc::clone(&asleep));
                let handle = thread::Builder::new()
                    .name(format!("a2ml-batch-{k}"))
                    .spawn(move || watch(&shared, &flag, patience))
                    .ok()?;
                Some(Helper { thread: handle.thread().clone(), asleep })
            })
            .collect();
        Self { shared, helpers }
    }

    /// Runs `work` on the calling thread and on every helper that comes while it runs; returns
    /// when the calling thread's run has returned and no helper is inside. `work` must share
    /// itself out and return once nothing is left. A panic of any run is resumed here.
    ///
    /// Waking a helper that sleeps costs its waker 15–20 µs on our virtual machines (measured:
    /// the wake-up crosses the hypervisor), and the helper comes some 40 µs later. `long`
    /// says the work takes far longer than that (hundreds of microseconds): sleeping helpers
    /// are then woken before the caller starts. Otherwise they are woken after its run, for
    /// the calls that follow; a helper that only dozes (see `watch`) is never woken, it
    /// looks for work on its own.
    pub fn run(&self, work: &(dyn Fn() + Sync), long: bool) {
        let shared = &*self.shared;
        if self.helpers.is_empty()
            || shared.posting.compare_exchange(false, true, SeqCst, SeqCst).is_err()
        {
            return work();
        }
        let posted: Work<'_> = work;
        shared.posted.store(&posted as *const Work<'_> as usize, SeqCst);
        shared.generation.fetch_add(1, SeqCst);
        if long {
            self.wake();
        }
        let own = catch_unwind(AssertUnwindSafe(work));
        // From here no helper enters; the ones inside are at most a piece from the end.
        shared.posted.store(0, SeqCst);
        let mut spins: u32 = 0;
        while shared.inside.load(SeqCst) != 0 {
            pause(spins);
            spins = spins.wrapping_add(1);
        }
        let helpers = shared.panic.lock().unwrap_or_else(PoisonError::into_inner).take();
        shared.posting.store(false, SeqCst);
        if !long {
            self.wake();
        }
        if let Err(panic) = own {
            resume_unwind(panic);
        }
        if let Some(panic) = helpers {
            resume_unwind(panic);
        }
    }

    /// Unparks the helpers that sleep.
    fn wake(&self) {
        for helper in &self.helpers {
            if helper.asleep.swap(false, SeqCst) {
                helper.thread.unpark();
            }
        }
    }
}

/// A helper's life: run each posted work once; after the last, spin for [`LINGER`], then doze
/// (look every [`DOZE`], woken by its own timer, which costs no caller anything) until
/// [`IDLE`] has passed, then sleep until a caller wakes it.
fn watch(shared: &Shared, asleep: &AtomicBool, patience: Patience) {
    let mut done = 0;
    let mut idle_since = Instant::now();
    // Wrapping: a helper lives as long as its process, and only the counter's low bits matter.
    let mut spins: u32 = 0;
    loop {
        spins = spins.wrapping_add(1);
        let generation = shared.generation.load(SeqCst);
        if generation != done {
            // A post since the last look. `posted` is stored before the count moves, so 0
            // here means that post has ended already.
            if shared.posted.load(SeqCst) != 0 {
                // Counted in before reading the address: a caller that clears `posted` after
                // this count waits for it; one that cleared it before is seen as 0 below.
                shared.inside.fetch_add(1, SeqCst);
                let address = shared.posted.load(SeqCst);
                if address != 0 {
                    // SAFETY: a nonzero `posted` is the address of a live `Work` on its
                    // caller's stack: the caller clears it before its frame ends and then
                    // waits until `inside` is 0, which this helper's count keeps it from being
                    // until the run below has returned.
                    #[allow(unsafe_code)]
                    let work: Work<'_> = unsafe { *(address as *const Work<'_>) };
                    if let Err(panic) = catch_unwind(AssertUnwindSafe(work)) {
                        *shared.panic.lock().unwrap_or_else(PoisonError::into_inner) = Some(panic);
                    }
                }
                shared.inside.fetch_sub(1, SeqCst);
                idle_since = Instant::now();
            }
            done = generation;
            continue;
        }
        pause(spins);
        // The clock read every 256 spins (some microseconds): cheap against the spin itself.
        if spins % 256 != 255 {
            continue;
        }
        let idle = idle_since.elapsed();
        if idle < patience.linger {
            continue;
        }
        if idle < patience.idle {
            thread::park_timeout(patience.doze);
            continue;
        }
        // Asleep first, then one more look: a caller that posts after this look sees the flag
        // and unparks (an unpark before the park makes it return at once).
        asleep.store(true, SeqCst);
        if shared.generation.load(SeqCst) == done {
            thread::park();
        }
        asleep.store(false, SeqCst);
        idle_since = Instant::now();
    }
}

/// One wait of a spinning thread: mostly the processor's pause, every [`YIELD_EVERY`]th time
/// the rest of the time slice. A woken helper is often placed on its waker's core; there it
/// would take the time the caller needs (and a caller waiting for a helper would starve it),
/// so the spin gives the core away, and the scheduler soon moves one of the two.
#[inline]
fn pause(spins: u32) {
    if spins % YIELD_EVERY == YIELD_EVERY - 1 {
        thread::yield_now();
    } else {
        std::hint::spin_loop();
    }
}

/// Spins between two yields of [`pause`].
const YIELD_EVERY: u32 = 16;

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU64;

    /// `pieces` pieces shared out by a counter; each adds its index to a sum.
    fn sum_of_pieces(team: &Team, pieces: u64) -> (u64, u64) {
        let (next, sum, runs) = (AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0));
        let work = || {
            runs.fetch_add(1, SeqCst);
            loop {
                let piece = next.fetch_add(1, SeqCst);
                if piece >= pieces {
                    return;
                }
                sum.fetch_add(piece, SeqCst);
                std::hint::black_box((0..2_000).sum::<u64>());
            }
        };
        team.run(&work, pieces % 2 == 0);
        (sum.load(SeqCst), runs.load(SeqCst))
    }

    /// Short waits, so that the tests see helpers spin, doze and sleep.
    const QUICK: Patience = Patience {
        linger: Duration::from_micros(300),
        doze: Duration::from_micros(100),
        idle: Duration::from_millis(3),
    };

    #[test]
    fn the_variable_sets_the_threads_of_a_batch() {
        assert_eq!(helpers_for(None, 2), 1);
        assert_eq!(helpers_for(None, 1), 0);
        assert_eq!(helpers_for(None, 64), MOST_HELPERS);
        assert_eq!(helpers_for(Some("1"), 8), 0);
        assert_eq!(helpers_for(Some(" 3 "), 8), 2);
        assert_eq!(helpers_for(Some("0"), 4), 3);
        assert_eq!(helpers_for(Some("many"), 4), 3);
        assert_eq!(helpers_for(Some(""), 2), 1);
    }

    #[test]
    fn the_process_keeps_one_team() {
        assert!(std::ptr::eq(team(), team()));
    }

    #[test]
    fn every_piece_is_done_once_with_or_without_helpers() {
        for helpers in [0, 1, 3] {
            let team = Team::new(helpers, QUICK);
            for round in 0..300 {
                // Now and then long enough for the helpers to doze, or to fall asleep.
                match round % 50 {
                    24 => thread::sleep(Duration::from_millis(1)),
                    49 => thread::sleep(Duration::from_millis(6)),
                    _ => {}
                }
                let pieces = round % 37;
                let (sum, runs) = sum_of_pieces(&team, pieces);
                assert_eq!(sum, pieces * pieces.saturating_sub(1) / 2, "{helpers} helpers");
                assert!((1..=1 + helpers as u64).contains(&runs), "{runs} runs");
            }
        }
    }

    #[test]
    fn callers_at_once_each_get_their_own_work_done() {
        let team = Team::new(1, QUICK);
        thread::scope(|scope| {
            for _ in 0..4 {
                scope.spawn(|| {
                    for pieces in 0..100 {
                        assert_eq!(
                            sum_of_pieces(&team, pieces).0,
                            pieces * pieces.saturating_sub(1) / 2
                        );
                    }
                });
            }
        });
    }

    #[test]
    fn a_helpers_panic_reaches_the_caller() {
        let team = Team::new(1, QUICK);
        let caller = thread::current().id();
        // Only a helper panics; the caller's run returns. If no helper came, nothing panics,
        // so the call is repeated until one did.
        let helped = (0..1_000).any(|_| {
            let work = || {
                if thread::current().id() != caller {
                    panic!("helper");
                }
                thread::sleep(Duration::from_micros(200));
            };
            catch_unwind(AssertUnwindSafe(|| team.run(&work, true))).is_err()
        });
        assert!(helped, "no helper ever ran the work");
        // The team still works after it.
        assert_eq!(sum_of_pieces(&team, 10).0, 45);
    }
}
