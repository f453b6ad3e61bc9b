//! The stages' parallel parts: work cut into pieces fixed by the input alone (never by the
//! number of threads), run on bevy's compute pool when there is enough of it and more than
//! one thread, their results joined in the pieces' order. So every result, down to the
//! rounding of a sum, is the same whatever the thread count. (The continuous mode's bands,
//! one per thread, keep that by giving the single timeline's result exactly; each runs on
//! one thread, [`one_thread_each`].) The calling thread takes pieces too, each thread its own
//! share first, and waits for the last ones spinning; after a pass the workers spin a while
//! rather than sleep, so that the next pass finds them awake (`keep_awake_for`).

use std::ops::Range;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

use bevy::tasks::futures_lite::future::yield_now;
use bevy::tasks::{ComputeTaskPool, TaskPool};
use crossbeam_utils::CachePadded;

/// Below this many balls a stage's work runs on the calling thread: splitting it costs more
/// than it saves.
pub const PARALLEL_MIN_BALLS: usize = 20_000;

/// Balls in each piece of a pass over every ball: big enough that a piece outweighs handing
/// it to a thread, small enough for 16 threads to share 100,000 balls.
pub const BALLS_PER_PIECE: usize = 4096;

/// The balls `0..count` in pieces of [`BALLS_PER_PIECE`].
pub fn piece_ranges(count: usize) -> impl Iterator<Item = Range<usize>> + Clone {
    (0..count.div_ceil(BALLS_PER_PIECE))
        .map(move |piece| piece * BALLS_PER_PIECE..((piece + 1) * BALLS_PER_PIECE).min(count))
}

/// `0..count` cut into `parts` consecutive ranges as near equal as can be (some empty when
/// there are more parts than items): bands of rows or cells for the threads to share.
pub fn split_evenly(
    count: usize,
    parts: usize,
) -> impl ExactSizeIterator<Item = Range<usize>> + Clone {
    (0..parts).map(move |part| count * part / parts..count * (part + 1) / parts)
}

/// The compute pool the parallel parts run on.
pub fn compute_pool() -> &'static TaskPool {
    ComputeTaskPool::get_or_init(TaskPool::default)
}

/// The threads that work on a stage's parallel parts: the compute pool's workers and the
/// thread that runs the stage, which takes its share while it waits for them.
pub fn threads_at_work() -> usize {
    compute_pool().thread_num() + 1
}

/// Whether a stage's work over `balls` balls runs in parallel: enough balls, more than one
/// thread at work, and not within [`one_thread_each`] work.
pub fn worth_splitting(balls: usize) -> bool {
    balls >= PARALLEL_MIN_BALLS && threads_at_work() > 1 && !ONE_THREAD.get()
}

thread_local! {
    /// Set while this thread runs work given one thread of its own.
    static ONE_THREAD: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// `work` done on each of `pieces` as [`in_pieces`] does, each piece on one thread: the work
/// within a piece is not split again.
pub fn one_thread_each<P: Send, R: Send + 'static>(
    pieces: impl Iterator<Item = P>,
    parallel: bool,
    work: impl Fn(P) -> R + Sync,
) -> Vec<R> {
    in_pieces(pieces, parallel, |piece| {
        let _one_thread = OneThread::claim();
        work(piece)
    })
}

/// While alive, this thread's work is not split ([`worth_splitting`] is false); it restores
/// what was before when dropped, even by a panic.
struct OneThread(bool);

impl OneThread {
    fn claim() -> Self {
        Self(ONE_THREAD.replace(true))
    }
}

impl Drop for OneThread {
    fn drop(&mut self) {
        ONE_THREAD.set(self.0);
    }
}

/// `work` done on each of `pieces`, on the compute pool if `parallel`, the results in the
/// pieces' order; the pool's workers are then kept awake a while for the next pass
/// (`keep_awake_for`).
///
/// The calling thread does not hand every piece to the pool and wait: a task for each worker
/// and the calling thread itself take the pieces, each its own share first ([`SharedPieces`]),
/// and the calling thread, out of pieces, waits spinning ([`SPIN_AT_THE_JOIN`]) for those
/// still under way. A thread that waits asleep takes 20–60 µs on this project's machine to wake,
/// and a step makes several passes.
pub fn in_pieces<P: Send, R: Send + 'static>(
    pieces: impl Iterator<Item = P>,
    parallel: bool,
    work: impl Fn(P) -> R + Sync,
) -> Vec<R> {
    if !parallel {
        return pieces.map(work).collect();
    }
    let pieces: Vec<P> = pieces.collect();
    let helpers = (threads_at_work() - 1).min(pieces.len().saturating_sub(1));
    let state = SharedPieces::new(pieces, helpers + 1);
    let (shared, work) = (&state, &work);
    let mut own = Ok(());
    compute_pool().scope(|scope| {
        for helper in 1..=helpers {
            scope.spawn(async move { shared.take_each(helper, work) });
        }
        own = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| shared.take_each(0, work)));
        shared.wait_spinning_for_all(SPIN_AT_THE_JOIN);
    });
    if let Err(panic) = own {
        std::panic::resume_unwind(panic);
    }
    keep_awake_for(AWAKE_AFTER_A_PASS);
    state.into_results()
}

/// How long the calling thread of a pass, out of pieces, spins waiting for the pieces still
/// under way before it waits asleep: about as long as the workers stay awake after a pass.
const SPIN_AT_THE_JOIN: std::time::Duration = std::time::Duration::from_micros(400);

/// The pieces of one pass, for threads to take, and their results. Each thread has a share,
/// consecutive pieces, and takes its own one after another before it helps with what is left
/// of the others'. So each thread works, pass after pass, on much the same part of the
/// arrays, and the threads meet at a count only at the end of a pass. Taken from one count
/// shared by every piece, as before, two threads at 100,000 balls were 5% slower in the
/// discrete mode and 1% in the continuous one, and 32% and 8% slower while the host kept the
/// two cores far apart (a cache line's round trip between them 387–438 ns, against 74–166 ns
/// otherwise: docs/performance.md, *Each thread its own share of a pass*).
struct SharedPieces<P, R> {
    pieces: Vec<Mutex<Option<P>>>,
    results: Vec<Mutex<Option<R>>>,
    /// Each thread's share, on a cache line of its own.
    shares: Vec<CachePadded<Share>>,
    /// How many pieces are done (or ended in a panic).
    done: AtomicUsize,
}

/// A thread's share of a pass's pieces: `next..end` are left to take.
struct Share {
    next: AtomicUsize,
    end: usize,
}

impl<P, R> SharedPieces<P, R> {
    /// `pieces` in `threads` shares.
    fn new(pieces: Vec<P>, threads: usize) -> Self {
        let shares = split_evenly(pieces.len(), threads)
            .map(|share| {
                let next = AtomicUsize::new(share.start);
                CachePadded::new(Share {
                    next,
                    end: share.end,
                })
            })
            .collect();
        let pieces: Vec<_> = pieces
            .into_iter()
            .map(|piece| Mutex::new(Some(piece)))
            .collect();
        let results = pieces.iter().map(|_| Mutex::new(None)).collect();
        Self {
            pieces,
            results,
            shares,
            done: AtomicUsize::new(0),
        }
    }

    fn count(&self) -> usize {
        self.pieces.len()
    }

    /// Takes the pieces of share `own`, then those left in the others', and does `work` on
    /// each until none is left.
    fn take_each(&self, own: usize, work: &impl Fn(P) -> R) {
        let mut counted = CountedDone {
            done: &self.done,
            pieces: 0,
        };
        let shares = self.shares.len();
        for share in (0..shares).map(|k| &self.shares[(own + k) % shares]) {
            loop {
                let k = share.next.fetch_add(1, Ordering::Relaxed);
                if k >= share.end {
                    break;
                }
                // Counted before the work: the count is only told when this thread is done.
                counted.pieces += 1;
                let piece = self.pieces[k].lock().map(|mut piece| piece.take());
                if let Ok(Some(piece)) = piece {
                    let result = work(piece);
                    if let Ok(mut slot) = self.results[k].lock() {
                        *slot = Some(result);
                    }
                }
            }
        }
    }

    /// Spins until every piece is done, or for `span` at most.
    fn wait_spinning_for_all(&self, span: std::time::Duration) {
        let started = Instant::now();
        while self.done.load(Ordering::Acquire) < self.count() && started.elapsed() < span {
            std::hint::spin_loop();
        }
    }

    /// The results in the pieces' order, once every piece is done.
    fn into_results(self) -> Vec<R> {
        let results = self.results.into_iter().map(Mutex::into_inner);
        results
            .map(|result| result.ok().flatten())
            .map(|result| result.expect("a pass ends with every piece done"))
            .collect()
    }
}

/// Counts a thread's pieces done when dropped, even by a panic, so that no one waits for them
/// for ever.
struct CountedDone<'a> {
    done: &'a AtomicUsize,
    pieces: usize,
}

impl Drop for CountedDone<'_> {
    fn drop(&mut self) {
        self.done.fetch_add(self.pieces, Ordering::Release);
    }
}

/// How long the pool's workers stay awake after a pass: long enough for the next pass of a
/// step at 100,000 balls to find them awake (the serial parts between passes take up to
/// 0.25 ms there), short enough that a long serial part (a million balls' single timeline)
/// does not run beside a core kept busy for nothing, which slowed it by 4–5%.
const AWAKE_AFTER_A_PASS: std::time::Duration = std::time::Duration::from_micros(400);

/// Keeps every worker of the pool awake for `span` from now (or longer, if already asked):
/// each polls a task that yields at once until then. A worker gone to sleep takes 20–60 µs
/// to wake when a pass hands it work, and a step makes about six passes. Which thread takes
/// which piece is all this changes.
fn keep_awake_for(span: std::time::Duration) {
    let until = nanoseconds_now() + span.as_nanos() as u64;
    AWAKE_UNTIL.fetch_max(until, Ordering::Relaxed);
    let pool = compute_pool();
    let mut awake = AWAKE_TASKS.load(Ordering::Relaxed);
    while awake < pool.thread_num() {
        let counted = AWAKE_TASKS.compare_exchange_weak(
            awake,
            awake + 1,
            Ordering::Relaxed,
            Ordering::Relaxed,
        );
        if let Err(now) = counted {
            awake = now;
            continue;
        }
        awake += 1;
        let task = pool.spawn(async {
            while nanoseconds_now() < AWAKE_UNTIL.load(Ordering::Relaxed) {
                yield_now().await;
            }
            AWAKE_TASKS.fetch_sub(1, Ordering::Relaxed);
        });
        task.detach();
    }
}

/// The time [`keep_awake_for`] keeps the workers awake until, in [`nanoseconds_now`]'s count.
static AWAKE_UNTIL: AtomicU64 = AtomicU64::new(0);

/// The tasks keeping workers awake now.
static AWAKE_TASKS: AtomicUsize = AtomicUsize::new(0);

/// Nanoseconds since this was first asked.
fn nanoseconds_now() -> u64 {
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

/// The parts of `items` in `ranges`, which must be in order and not overlap (gaps between
/// them are left out): disjoint slices that can go to different threads. Panics if a range
/// starts before the last one ended or ends past `items`.
pub fn carve<T>(
    mut items: &mut [T],
    ranges: impl Iterator<Item = Range<usize>>,
) -> impl Iterator<Item = &mut [T]> {
    let mut taken = 0;
    ranges.map(move |range| {
        take_front(&mut items, range.start - taken);
        taken = range.end;
        take_front(&mut items, range.len())
    })
}

/// The first `len` of `items`, which keeps the rest. Panics if `items` is shorter.
pub fn take_front<'a, T>(items: &mut &'a mut [T], len: usize) -> &'a mut [T] {
    let (front, rest) = std::mem::take(items).split_at_mut(len);
    *items = rest;
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pieces_come_back_in_order_and_alike_on_one_thread_or_many() {
        let mut values: Vec<u64> = (0..50_000).collect();
        let run = |values: &mut [u64], parallel: bool| {
            in_pieces(values.chunks_mut(BALLS_PER_PIECE), parallel, |piece| {
                piece.iter_mut().for_each(|value| *value *= 3);
                piece.iter().sum::<u64>()
            })
        };
        let serial = run(&mut values, false);
        let parallel = run(&mut values, true);
        assert_eq!(serial.len(), 50_000usize.div_ceil(BALLS_PER_PIECE));
        // The second pass tripled the first's values, piece by piece.
        let tripled: Vec<u64> = serial.iter().map(|sum| sum * 3).collect();
        assert_eq!(parallel, tripled);
        assert_eq!(values[49_999], 49_999 * 9);
    }

    #[test]
    fn each_thread_takes_its_own_share_first_then_what_the_others_left() {
        // Ten pieces in three shares (3, 3 and 4 pieces); each test takes them on one thread.
        let taken_by = |own: &[usize]| {
            let shared = SharedPieces::new((0..10).collect(), 3);
            let order = Mutex::new(Vec::new());
            for &share in own {
                shared.take_each(share, &|piece: usize| {
                    order.lock().unwrap().push(piece);
                    piece * 2
                });
            }
            assert_eq!(shared.done.load(Ordering::Acquire), 10);
            let results = shared.into_results();
            assert_eq!(results, (0..10).map(|piece| piece * 2).collect::<Vec<_>>());
            order.into_inner().unwrap()
        };
        // A thread alone takes its share, then the next shares round from it.
        assert_eq!(taken_by(&[0]), (0..10).collect::<Vec<_>>());
        assert_eq!(taken_by(&[1]), [3, 4, 5, 6, 7, 8, 9, 0, 1, 2]);
        assert_eq!(taken_by(&[2]), [6, 7, 8, 9, 0, 1, 2, 3, 4, 5]);
        // A thread that comes later finds every piece taken.
        assert_eq!(taken_by(&[2, 0]), [6, 7, 8, 9, 0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn a_piece_that_panics_makes_the_pass_panic_and_the_next_pass_runs() {
        for bad in [0, 5, 12] {
            let pass = std::panic::catch_unwind(|| {
                in_pieces(0..13, true, |piece: u32| {
                    assert_ne!(piece, bad, "piece {bad} fails");
                    piece * 2
                })
            });
            assert!(pass.is_err(), "piece {bad}");
            let doubled = in_pieces(0..13, true, |piece: u32| piece * 2);
            assert_eq!(doubled, (0..13).map(|piece| piece * 2).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_pass_keeps_the_workers_awake_for_a_while_and_then_lets_them_sleep() {
        let mut values: Vec<u64> = (0..50_000).collect();
        let pass = |values: &mut [u64]| {
            let sums = in_pieces(values.chunks_mut(BALLS_PER_PIECE), true, |piece| {
                piece.iter().sum::<u64>()
            });
            assert_eq!(sums.iter().sum::<u64>(), 50_000 * 49_999 / 2);
        };
        let before = nanoseconds_now();
        pass(&mut values);
        let awake_for = AWAKE_UNTIL.load(Ordering::Relaxed).saturating_sub(before);
        assert!(
            awake_for >= AWAKE_AFTER_A_PASS.as_nanos() as u64,
            "{awake_for} ns"
        );
        // Passes while the workers are awake, keeping them awake longer, add no task.
        let workers = compute_pool().thread_num();
        for _ in 0..20 {
            pass(&mut values);
            assert!(AWAKE_TASKS.load(Ordering::Relaxed) <= workers);
        }
        // Some time after the last pass, every worker may sleep again.
        let started = Instant::now();
        while AWAKE_TASKS.load(Ordering::Relaxed) > 0 {
            assert!(
                started.elapsed().as_secs() < 10,
                "the workers are kept awake"
            );
            std::thread::yield_now();
        }
    }

    #[test]
    fn carving_leaves_the_gaps_out() {
        let mut items: Vec<u32> = (0..10).collect();
        let parts: Vec<Vec<u32>> = carve(&mut items, [1..3, 3..4, 6..9].into_iter())
            .map(|part| part.to_vec())
            .collect();
        assert_eq!(parts, [vec![1, 2], vec![3], vec![6, 7, 8]]);
    }
}
