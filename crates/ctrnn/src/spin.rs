//! A process-wide pool of helper threads that stay awake between small jobs, for the steps of a
//! [`Batch`](crate::Batch) too small for rayon.
//!
//! A closed-loop task steps its batch once per time step and spends the time between two steps
//! in the caller's own code (a Python environment, say). A step of a few thousand rows is tens
//! of microseconds of work; handed to rayon, it ran twice as slowly as on one thread, because
//! rayon's workers fall asleep during the caller's part and waking a sleeping thread costs about
//! as much as the step. The helpers here instead wait for [`SPIN`] after each job before they
//! park, looking for the next job and yielding the core in between, so that the next step, a few
//! tens of microseconds later, finds them awake.
//!
//! [`try_for_each_zip`] runs a function on every index of two slices of equal length: the caller
//! and the helpers take chunks of indices from a shared counter until none are left, so a helper
//! that is late (asleep, or descheduled) only means the caller does more of the work itself.
//! Which thread runs an index never changes what the function computes.
//!
//! The pool starts on first use with one helper per core beyond the first, as many as rayon's
//! global pool has threads beyond one (so `RAYON_NUM_THREADS=1`, or a single core, starts none).
//! One caller at a time uses it: another caller meanwhile, or a call from a rayon worker (whose
//! siblings already fill the cores), runs its indices on its own thread, in order. The helpers
//! live until the process ends; once idle for [`SPIN`] they are parked and cost nothing.

use std::any::Any;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::thread::{self, Thread};
use std::time::{Duration, Instant};

/// How long a helper waits awake for the next job before it parks. A closed-loop step comes
/// back after the caller's part of a time step, about 25 us for 2000 NumPy rows, and waking a
/// parked thread costs about as much as a step of that size; 200 us covers the caller's part
/// several times over, and bounds what an idle helper burns after the last step to a fifth of a
/// millisecond (less on a busy machine, where its yields give the core away).
pub const SPIN: Duration = Duration::from_micros(200);

/// Chunks per thread that the indices are cut into: enough for an even finish when one thread
/// starts late, few enough that taking a chunk (one contended atomic add) costs little.
const CHUNKS_PER_THREAD: usize = 8;

/// The work of one call, seen from a helper: runs its share and returns.
type Job = dyn Fn() + Sync;

struct Pool {
    /// The helpers' threads, set once they are started.
    threads: OnceLock<Vec<Thread>>,
    /// Set by helper `i` before it parks; the caller of a new job then unparks it.
    asleep: Vec<AtomicBool>,
    /// Whether a caller holds the pool.
    held: AtomicBool,
    /// Bumped by each new job; a helper looks for the job when it sees a number it has not seen.
    epoch: AtomicUsize,
    /// The current job, or null: points to a `&Job` on the caller's stack.
    job: AtomicPtr<&'static Job>,
    /// Helpers that may be reading `job` or running it; the caller returns only once it is 0.
    users: AtomicUsize,
}

/// The pool, started on first use; `None` when there is no core to spare.
fn pool() -> Option<&'static Pool> {
    static POOL: OnceLock<Option<&'static Pool>> = OnceLock::new();
    *POOL.get_or_init(start)
}

/// How many helpers the pool has (0 when it has none); starts it if need be. Call it from outside
/// rayon's workers, so that it counts the global pool's threads.
pub fn helpers() -> usize {
    pool().map_or(0, |p| p.threads.get().map_or(0, Vec::len))
}

fn start() -> Option<&'static Pool> {
    let cores = thread::available_parallelism().map_or(1, |n| n.get());
    let count = rayon::current_num_threads().min(cores).saturating_sub(1);
    if count == 0 {
        return None;
    }
    // Leaked: the helpers hold it for as long as the process lives.
    let pool: &'static Pool = Box::leak(Box::new(Pool {
        threads: OnceLock::new(),
        asleep: (0..count).map(|_| AtomicBool::new(false)).collect(),
        held: AtomicBool::new(false),
        epoch: AtomicUsize::new(0),
        job: AtomicPtr::new(std::ptr::null_mut()),
        users: AtomicUsize::new(0),
    }));
    let threads: Vec<Thread> = (0..count)
        .map_while(|i| {
            thread::Builder::new()
                .name(format!("ctrnn-spin-{i}"))
                .spawn(move || serve(pool, i))
                .ok()
                .map(|h| h.thread().clone())
        })
        .collect();
    if threads.is_empty() {
        return None;
    }
    let _ = pool.threads.set(threads);
    Some(pool)
}

/// Helper `i`'s life: wait for a job (spinning, then parked), run its share, again.
fn serve(pool: &'static Pool, i: usize) {
    let mut seen = 0;
    loop {
        let since = Instant::now();
        loop {
            let epoch = pool.epoch.load(Ordering::SeqCst);
            if epoch != seen {
                seen = epoch;
                break;
            }
            if since.elapsed() >= SPIN {
                // Announce the sleep, then look once more: a caller bumps the epoch before it
                // looks at `asleep`, so one of the two sees the other (both sequentially
                // consistent) and a job is never left without a wake-up.
                pool.asleep[i].store(true, Ordering::SeqCst);
                if pool.epoch.load(Ordering::SeqCst) == seen {
                    thread::park();
                }
                pool.asleep[i].store(false, Ordering::SeqCst);
            } else {
                // Yielding, not a bare spin: on an idle core it returns at once (a wait of well
                // under a microsecond), and on a busy machine it lets the other threads run, the
                // caller among them; a bare spin then took their time, and steps were 1.5 to 2
                // times slower than on one thread.
                thread::yield_now();
            }
        }
        // Counted as a user before the job is read: a caller that has withdrawn the job waits
        // for `users` to reach 0, so the job outlives every helper that saw it.
        pool.users.fetch_add(1, Ordering::SeqCst);
        let job = pool.job.load(Ordering::SeqCst);
        if !job.is_null() {
            // SAFETY: the job is on the caller's stack until `users` is 0 again (see `run`).
            #[allow(unsafe_code)]
            let job: &Job = unsafe { *job };
            job();
        }
        pool.users.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Holds the pool while a caller's job is out; withdrawing it waits until no helper is in it.
struct Lease {
    pool: &'static Pool,
}

impl Drop for Lease {
    fn drop(&mut self) {
        // Also on unwinding: the job lives on the caller's stack and must not be left behind.
        self.pool.job.store(std::ptr::null_mut(), Ordering::SeqCst);
        let since = Instant::now();
        while self.pool.users.load(Ordering::SeqCst) != 0 {
            // A helper finishes its chunk within microseconds unless it was descheduled.
            if since.elapsed() < SPIN {
                std::hint::spin_loop();
            } else {
                thread::yield_now();
            }
        }
        self.pool.held.store(false, Ordering::Release);
    }
}

/// Runs `job` on the calling thread and on every helper, and returns once none runs it; or only
/// on the calling thread when the pool has no helper or another caller holds it.
fn run(job: &(dyn Fn() + Sync)) {
    // Looked at first: from a rayon worker, `pool` would count that pool's threads.
    if rayon::current_thread_index().is_some() {
        return job();
    }
    let Some(pool) = pool() else {
        return job();
    };
    if pool
        .held
        .compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed)
        .is_err()
    {
        return job();
    }
    // SAFETY: only the lifetime is erased. The lease, made after `erased` so that it is dropped
    // first, withdraws the job and waits until no helper uses it before this function returns or
    // unwinds, so no helper reads `erased` or `job` past their life.
    #[allow(unsafe_code)]
    let erased: &'static Job =
        unsafe { std::mem::transmute::<&(dyn Fn() + Sync), &'static Job>(job) };
    let slot = &erased;
    let lease = Lease { pool };
    pool.job.store(
        slot as *const &'static Job as *mut &'static Job,
        Ordering::SeqCst,
    );
    pool.epoch.fetch_add(1, Ordering::SeqCst);
    if let Some(threads) = pool.threads.get() {
        for (t, asleep) in threads.iter().zip(&pool.asleep) {
            if asleep.load(Ordering::SeqCst) {
                t.unpark();
            }
        }
    }
    job();
    drop(lease);
}

/// A pointer to an array whose elements are handed out one index to one thread.
struct Shared<T>(*mut T);

// SAFETY: `try_for_each_zip` hands each index to exactly one thread, so no two threads reach the
// same element; the elements are `Send`.
#[allow(unsafe_code)]
unsafe impl<T: Send> Sync for Shared<T> {}

impl<T> Shared<T> {
    /// The element at `i`.
    ///
    /// # Safety
    /// `i` is in bounds, and no other reference to the element is alive.
    #[allow(unsafe_code, clippy::mut_from_ref)]
    unsafe fn at(&self, i: usize) -> &mut T {
        unsafe { &mut *self.0.add(i) }
    }
}

/// Calls `f(i, &mut a[i], &mut b[i])` for every index of `a` and `b` (equal lengths), on the
/// calling thread and the pool's helpers. Returns the error of the lowest failing index, as a
/// loop in index order would: every index below it has run, and indices above it may or may not
/// have. A panic in `f` is raised again on the calling thread once no helper runs `f`.
pub fn try_for_each_zip<A: Send, B: Send, E: Send>(
    a: &mut [A],
    b: &mut [B],
    f: impl Fn(usize, &mut A, &mut B) -> Result<(), E> + Sync,
) -> Result<(), E> {
    assert_eq!(
        a.len(),
        b.len(),
        "try_for_each_zip needs slices of equal length"
    );
    let len = a.len();
    let threads = match rayon::current_thread_index() {
        Some(_) => 1,
        None => 1 + helpers(),
    };
    let chunk = len.div_ceil(threads * CHUNKS_PER_THREAD).max(1);
    let next = AtomicUsize::new(0);
    // The lowest failing index so far (usize::MAX: none): indices above it are skipped.
    let stop = AtomicUsize::new(usize::MAX);
    let failure: Mutex<Option<(usize, E)>> = Mutex::new(None);
    let panic: Mutex<Option<Box<dyn Any + Send>>> = Mutex::new(None);
    let (pa, pb) = (Shared(a.as_mut_ptr()), Shared(b.as_mut_ptr()));
    let share = || loop {
        let from = next.fetch_add(chunk, Ordering::Relaxed);
        if from >= len || from > stop.load(Ordering::Relaxed) {
            return;
        }
        for i in from..(from + chunk).min(len) {
            if i > stop.load(Ordering::Relaxed) {
                return;
            }
            // SAFETY: `i < len`, and the counter hands each chunk, so each index, out once.
            #[allow(unsafe_code)]
            let (x, y) = unsafe { (pa.at(i), pb.at(i)) };
            if let Err(e) = f(i, x, y) {
                let mut failed = failure.lock().unwrap_or_else(|p| p.into_inner());
                if failed.as_ref().is_none_or(|(at, _)| i < *at) {
                    *failed = Some((i, e));
                }
                stop.fetch_min(i, Ordering::Relaxed);
                return;
            }
        }
    };
    let guarded = || {
        if let Err(p) = catch_unwind(AssertUnwindSafe(share)) {
            stop.store(0, Ordering::Relaxed);
            let mut slot = panic.lock().unwrap_or_else(|p| p.into_inner());
            slot.get_or_insert(p);
        }
    };
    run(&guarded);
    if let Some(p) = panic.into_inner().unwrap_or_else(|p| p.into_inner()) {
        resume_unwind(p);
    }
    match failure.into_inner().unwrap_or_else(|p| p.into_inner()) {
        Some((_, e)) => Err(e),
        None => Ok(()),
    }
}
