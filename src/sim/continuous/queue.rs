//! The timeline's queue of impacts, earliest first. Most of a step's impacts are predicted
//! at its start: those are sorted once and read in order. The ones predicted during the step
//! (after an impact redirects a ball) fall into buckets by time, as in a calendar queue: only
//! the impacts of the buckets the timeline has reached are in a heap, which stays small (17
//! impacts on average, at 100,000 balls as at a million), and each later bucket's is a plain
//! list until the timeline reaches it. Taking the earlier of the two heads gives the order one
//! heap of them all would give. The first predictions are sorted the same way: spread over
//! buckets of time, a few to a bucket, and each bucket sorted.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::impact::Impact;

/// Impacts, taken earliest first (then by [`Impact`]'s order of the balls).
#[derive(Debug, Default)]
pub struct ImpactQueue {
    /// The impacts predicted at the start of the step, in order; `sorted[next..]` are left.
    sorted: Vec<Impact>,
    next: usize,
    /// The impacts predicted since, by bucket of time.
    later: Buckets,
    /// Where each bucket of [`sort_in_buckets`] ends, kept from step to step.
    bucket_ends: Vec<u32>,
}

impl ImpactQueue {
    /// Empties the queue and fills it with the step's first predictions; those predicted
    /// during the step will mostly lie within `horizon` seconds of its start.
    pub fn start(&mut self, impacts: impl Iterator<Item = Impact> + Clone, horizon: f64) {
        // The buckets' count only sets how the sort splits its work, never the order: an upper
        // bound on the impacts will do, and spares a pass over them (6.5 MB at a million).
        let count = impacts
            .size_hint()
            .1
            .unwrap_or_else(|| impacts.clone().count());
        let buckets = TimeBuckets::over(horizon, count / IMPACTS_PER_SORTED_BUCKET);
        sort_in_buckets(impacts, buckets, (&mut self.sorted, &mut self.bucket_ends));
        self.next = 0;
        self.later.start(horizon, self.sorted.len());
    }

    /// Adds an impact predicted during the step.
    pub fn push(&mut self, impact: Impact) {
        self.later.push(impact);
    }

    /// How many of the step's first predictions have been taken: [`ahead`](Self::ahead)
    /// gives the same ones until this changes.
    pub fn first_taken(&self) -> usize {
        self.next
    }

    /// The step's first prediction `distance` places after the next one left: most likely
    /// taken soon (an impact predicted since may come first, or make it stale).
    pub fn ahead(&self, distance: usize) -> Option<&Impact> {
        self.sorted.get(self.next + distance)
    }

    /// The earliest impact predicted during the step in the buckets the timeline has reached:
    /// it may be taken next.
    pub fn earliest_later(&self) -> Option<&Impact> {
        self.later.earliest()
    }

    /// Whether an impact left comes before `impact` (in [`Impact`]'s order), the last one
    /// [`pop`](Self::pop) took: that pop reached its bucket, so an impact waiting in a later
    /// bucket's list comes after it, and only the two heads need be asked.
    pub fn has_before(&self, impact: &Impact) -> bool {
        self.sorted
            .get(self.next)
            .is_some_and(|first| first < impact)
            || self.later.earliest().is_some_and(|later| later < impact)
    }

    /// Puts back `impact`, the last one [`pop`](Self::pop) took: the queue then gives the
    /// impacts it would have given had it never been taken (their order is total: no two
    /// different impacts compare equal).
    pub fn put_back(&mut self, impact: Impact) {
        if self.next > 0 && self.sorted[self.next - 1] == impact {
            self.next -= 1;
        } else {
            self.later.push(impact);
        }
    }

    /// Takes the earliest impact left.
    pub fn pop(&mut self) -> Option<Impact> {
        let first = self.sorted.get(self.next);
        // The later impacts that may come before `first` join the heap: those of its bucket
        // and the ones before. Without a first, the next bucket with any, should none be left.
        match first {
            Some(first) => self.later.reach(self.later.bucket_of(first.time)),
            None => self.later.reach_next_if_empty(),
        }
        match (first, self.later.earliest()) {
            (Some(first), Some(later)) if later < first => self.later.pop(),
            (Some(&first), _) => {
                self.next += 1;
                Some(first)
            }
            (None, _) => self.later.pop(),
        }
    }
}

/// Impacts in buckets of time: those of the buckets the timeline has reached (up to `current`)
/// in a heap, each later bucket's in a list, heaped when the timeline reaches it. The bucket
/// of a time never decreases as the time grows (in `f64::total_cmp`'s order), so every impact
/// in a later bucket comes after every one in an earlier bucket. An impact pushed for a bucket
/// already reached goes into the heap, which orders it with the rest.
///
/// The heap holds only what the timeline has reached: heaping a bucket sooner (once the heap
/// ran dry, whatever bucket the next impact pushed fell in) let every impact predicted for the
/// times between pile into the heap, 450 of them on average at 100,000 balls and 5,100 at a
/// million, each pop a path through so many more levels.
#[derive(Debug, Default)]
struct Buckets {
    heap: BinaryHeap<Reverse<Impact>>,
    lists: Vec<Vec<Impact>>,
    /// The last bucket whose impacts are in the heap: the lists of it and of every bucket
    /// before it are empty.
    current: usize,
    /// Which bucket an impact's time falls in.
    by_time: TimeBuckets,
}

/// About this many impacts predicted at a step's start per bucket: the buckets in use then
/// hold about as many of the impacts predicted during the step.
const IMPACTS_PER_BUCKET: usize = 64;

/// Buckets at most: the lists' heads stay in the cache.
const MAX_BUCKETS: usize = 4096;

impl Buckets {
    /// Empty, in buckets over `horizon` seconds, as many as suit a step that started with
    /// `first` impacts.
    fn start(&mut self, horizon: f64, first: usize) {
        self.by_time = TimeBuckets::over(horizon, (first / IMPACTS_PER_BUCKET).min(MAX_BUCKETS));
        self.lists.resize_with(self.by_time.count, Vec::new);
        self.lists.truncate(self.by_time.count);
        self.lists.iter_mut().for_each(Vec::clear);
        self.heap.clear();
        self.current = 0;
    }

    /// The bucket of an impact at `time`.
    fn bucket_of(&self, time: f64) -> usize {
        self.by_time.of(time)
    }

    fn earliest(&self) -> Option<&Impact> {
        self.heap.peek().map(|Reverse(impact)| impact)
    }

    fn push(&mut self, impact: Impact) {
        let bucket = self.bucket_of(impact.time);
        if bucket <= self.current {
            self.heap.push(Reverse(impact));
        } else {
            self.lists[bucket].push(impact);
        }
    }

    /// The earliest of the impacts in the buckets reached: the earliest of all once the
    /// timeline has reached the bucket of the next impact it takes.
    fn pop(&mut self) -> Option<Impact> {
        self.heap.pop().map(|Reverse(impact)| impact)
    }

    /// Heaps the lists of every bucket up to `bucket`: every impact left in a list then comes
    /// after every impact of `bucket`.
    fn reach(&mut self, bucket: usize) {
        while self.current < bucket.min(self.lists.len() - 1) {
            self.current += 1;
            let list = &mut self.lists[self.current];
            if !list.is_empty() {
                self.heap.extend(list.drain(..).map(Reverse));
            }
        }
    }

    /// If the heap is empty, heaps the next bucket with impacts, if any: its earliest is the
    /// earliest left.
    fn reach_next_if_empty(&mut self) {
        if self.heap.is_empty()
            && let Some(next) =
                (self.current + 1..self.lists.len()).find(|&k| !self.lists[k].is_empty())
        {
            self.reach(next);
        }
    }
}

/// About this many of a step's first impacts to a bucket in [`sort_in_buckets`]: so few that
/// sorting a bucket takes a handful of comparisons.
const IMPACTS_PER_SORTED_BUCKET: usize = 4;

/// Buckets of time over `[0, horizon]` seconds: the bucket of a later time (in
/// `f64::total_cmp`'s order) is never an earlier one.
#[derive(Clone, Copy, Debug, Default)]
struct TimeBuckets {
    count: usize,
    /// Buckets per second.
    scale: f64,
}

impl TimeBuckets {
    /// `count` buckets (at least one) over `horizon` seconds; a horizon that is not a positive
    /// number puts everything into one bucket.
    fn over(horizon: f64, count: usize) -> Self {
        // At most `u32::MAX`, which `of` counts on.
        let count = count.clamp(1, u32::MAX as usize);
        let scale = if horizon > 0.0 && horizon.is_finite() {
            count as f64 / horizon
        } else {
            0.0
        };
        Self { count, scale }
    }

    /// The bucket of `time`.
    fn of(&self, time: f64) -> usize {
        let last = self.count - 1;
        if time.is_nan() && time.is_sign_positive() {
            return last; // after every other time
        }
        // `as` rounds down and saturates: a negative time (or NaN) to 0, a huge one to the max;
        // through `u32`, whose conversion takes fewer instructions than `usize`'s, for the same
        // bucket (there are at most `u32::MAX`).
        ((time * self.scale) as u32 as usize).min(last)
    }
}

/// `impacts` into `sorted`, in the order of `sort_unstable`: dealt into `buckets` by time (a
/// counting sort; `bucket_ends` ends as each bucket's end), then each bucket sorted on its
/// own. Every impact in a bucket comes before every one in a later bucket, and with a few to
/// a bucket each comparison of two `Impact`s, most of the cost, is spared all but a few times.
/// `sorted` keeps its buffer, grown to exactly what is needed, and what it held: every place
/// is written by the deal, so only places it never had are filled first (at a million balls
/// filling them all wrote 5 MB a step for nothing).
fn sort_in_buckets(
    impacts: impl Iterator<Item = Impact> + Clone,
    buckets: TimeBuckets,
    (sorted, bucket_ends): (&mut Vec<Impact>, &mut Vec<u32>),
) {
    let Some(first) = impacts.clone().next() else {
        sorted.clear();
        return;
    };
    // Each bucket's size, then where it starts.
    bucket_ends.clear();
    bucket_ends.resize(buckets.count, 0);
    for impact in impacts.clone() {
        bucket_ends[buckets.of(impact.time)] += 1;
    }
    let mut start = 0;
    for entry in bucket_ends.iter_mut() {
        (start, *entry) = (start + *entry, start);
    }
    // Each impact to the next place in its bucket: each entry moves on to its bucket's end.
    sorted.reserve_exact((start as usize).saturating_sub(sorted.len()));
    sorted.resize(start as usize, first);
    for impact in impacts {
        let next = &mut bucket_ends[buckets.of(impact.time)];
        sorted[*next as usize] = impact;
        *next += 1;
    }
    let mut start = 0;
    for &end in bucket_ends.iter() {
        sorted[start..end as usize].sort_unstable();
        start = end as usize;
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::sim::continuous::impact::Party;

    /// An impact at `time` between two of 50 balls, each with 0 to 2 hits.
    fn random_impact(rng: &mut ChaCha8Rng, time: f64) -> Impact {
        let mut ball = || {
            let index = rng.random_range(0..50u32);
            Party {
                slot: index as usize,
                index,
                hits: rng.random_range(0..3),
            }
        };
        let (i, j) = (ball(), ball());
        Impact::between(time, i, j)
    }

    /// `next`, from the queue, and the heap's next, each kept in its list; whether there were
    /// any (both sources must run dry together).
    fn take_alike(
        next: Option<Impact>,
        heap: &mut BinaryHeap<Reverse<Impact>>,
        (taken, expected): (&mut Vec<Impact>, &mut Vec<Impact>),
    ) -> bool {
        match (next, heap.pop()) {
            (Some(a), Some(Reverse(b))) => {
                taken.push(a);
                expected.push(b);
                true
            }
            (None, None) => false,
            (a, b) => panic!("one source ran dry first: {a:?} {b:?}"),
        }
    }

    #[test]
    fn the_two_sources_come_out_as_one_heap_of_them_all_would() {
        // The buckets span the step's first impacts (0.4 s), a tenth of it, ten times it, or
        // nothing (one bucket).
        for horizon in [0.4, 0.04, 4.0, 0.0, f64::NAN] {
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            let mut impact = |time: f64| random_impact(&mut rng, time);
            // Equal times on purpose: the balls' order must break the ties the same way.
            let first: Vec<Impact> = (0..3000).map(|k| impact((k % 40) as f64 * 0.01)).collect();
            let mut queue = ImpactQueue::default();
            queue.start(first.iter().copied(), horizon);
            let buckets = queue.later.lists.len();
            let mut heap: BinaryHeap<Reverse<Impact>> =
                first.iter().copied().map(Reverse).collect();
            let (mut taken, mut expected) = (Vec::new(), Vec::new());
            let (mut most_waiting, mut pops_with_lists_waiting) = (0, 0);
            for round in 0..6000 {
                // Now and then an impact predicted during the step: mostly at or after the
                // last taken, a few before it (a bucket already passed) or past the horizon.
                if round % 3 == 0 {
                    let now = taken.last().map_or(0.0, |i: &Impact| i.time);
                    let time = match round % 100 {
                        0 => now - 0.003,
                        51 => 0.45,
                        _ => now + (round % 7) as f64 * 0.005,
                    };
                    let later = impact(time);
                    queue.push(later);
                    heap.push(Reverse(later));
                    let waiting = queue.later.lists.iter().map(Vec::len).sum::<usize>();
                    most_waiting = most_waiting.max(waiting);
                }
                let next = queue.pop();
                // The heap holds no bucket after the next first prediction's, whatever bucket
                // the impacts pushed fell in.
                if let Some(first) = queue.sorted.get(queue.next) {
                    let reached = queue.later.current;
                    assert!(
                        reached <= queue.later.bucket_of(first.time),
                        "round {round}"
                    );
                    pops_with_lists_waiting += usize::from(
                        queue.later.lists[reached + 1..]
                            .iter()
                            .any(|list| !list.is_empty()),
                    );
                }
                if !take_alike(next, &mut heap, (&mut taken, &mut expected)) {
                    break;
                }
            }
            assert!(taken.len() > 4000, "{} taken", taken.len());
            assert_eq!(taken, expected, "horizon {horizon}");
            // Many of those pops left impacts waiting in later buckets, unless all fell in one.
            assert_eq!(
                pops_with_lists_waiting > 300,
                horizon > 0.0,
                "{pops_with_lists_waiting} pops with impacts waiting in later lists"
            );
            // The lists held impacts waiting for their bucket, unless there was one bucket.
            assert_eq!(buckets, 3000 / IMPACTS_PER_BUCKET);
            assert_eq!(
                most_waiting > 0,
                horizon > 0.0,
                "{most_waiting} waiting at most"
            );
        }
    }

    #[test]
    fn an_impact_put_back_comes_out_where_it_would_have() {
        // As the timeline does: the next impact taken before the last one's new predictions
        // are queued, and put back if one of them comes first. Equal times on purpose.
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let mut impact = |time: f64| random_impact(&mut rng, time);
        let first: Vec<Impact> = (0..2000).map(|k| impact((k % 40) as f64 * 0.01)).collect();
        let mut queue = ImpactQueue::default();
        queue.start(first.iter().copied(), 0.4);
        let mut heap: BinaryHeap<Reverse<Impact>> = first.iter().copied().map(Reverse).collect();
        let (mut taken, mut expected, mut put_back) = (Vec::new(), Vec::new(), [0, 0]);
        for round in 0..6000 {
            let now = taken.last().map_or(0.0, |i: &Impact| i.time);
            let new: Vec<Impact> = (0..round % 3)
                .map(|k| impact(now + ((round + k) % 5) as f64 * 0.004))
                .collect();
            heap.extend(new.iter().copied().map(Reverse));
            let mut next = queue.pop();
            new.into_iter().for_each(|impact| queue.push(impact));
            if let Some(impact) = next
                && queue.has_before(&impact)
            {
                let from_first = queue.next > 0 && queue.sorted[queue.next - 1] == impact;
                put_back[usize::from(from_first)] += 1;
                queue.put_back(impact);
                next = queue.pop();
            }
            if !take_alike(next, &mut heap, (&mut taken, &mut expected)) {
                break;
            }
        }
        assert!(taken.len() > 4000, "{} taken", taken.len());
        assert_eq!(taken, expected);
        // Put back both to the first predictions and among the later ones.
        assert!(
            put_back[0] > 50 && put_back[1] > 50,
            "{put_back:?} put back"
        );
    }

    #[test]
    fn sorting_in_buckets_gives_the_order_of_one_sort() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let party = |index: u32| Party {
            slot: index as usize,
            index,
            hits: 0,
        };
        // Times within the horizon, many equal; a few before it, past it, or not numbers.
        let time = |k: usize, rng: &mut ChaCha8Rng| match k % 50 {
            0 => -0.001,
            1 => 0.03,
            2 => f64::NAN,
            3 => -f64::NAN,
            4 => f64::INFINITY,
            5..=20 => (k % 7) as f64 / 420.0,
            _ => rng.random_range(0.0..1.0 / 60.0),
        };
        // One buffer throughout, as a timeline keeps it: growing, then shrinking, whatever it
        // held before never shows.
        let (mut sorted, mut ends) = (Vec::new(), Vec::new());
        for count in [0, 1, 7, 1000, 5000, 1000, 7] {
            let impacts: Vec<Impact> = (0..count)
                .map(|k| {
                    let pair = (rng.random_range(0..40), rng.random_range(40..80));
                    Impact::between(time(k, &mut rng), party(pair.0), party(pair.1))
                })
                .collect();
            let mut expected = impacts.clone();
            expected.sort_unstable();
            for buckets in [1, 3, count / IMPACTS_PER_SORTED_BUCKET, 4 * count] {
                let by_time = TimeBuckets::over(1.0 / 60.0, buckets);
                sort_in_buckets(impacts.iter().copied(), by_time, (&mut sorted, &mut ends));
                // `Debug` tells NaN times apart, where `==` would not.
                assert_eq!(
                    format!("{sorted:?}"),
                    format!("{expected:?}"),
                    "{count} impacts in {buckets} buckets"
                );
            }
        }
    }

    #[test]
    fn a_later_time_never_falls_into_an_earlier_bucket() {
        let mut buckets = Buckets::default();
        buckets.start(1.0 / 60.0, 100_000);
        let times = [
            -f64::NAN,
            f64::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            1e-300,
            0.004,
            1.0 / 60.0 - 1e-18,
            1.0 / 60.0,
            0.02,
            1e300,
            f64::INFINITY,
            f64::NAN,
        ];
        let found: Vec<usize> = times.iter().map(|&t| buckets.bucket_of(t)).collect();
        assert!(found.is_sorted(), "{found:?}");
        assert_eq!((found[0], found[12]), (0, buckets.lists.len() - 1));
        assert!(
            found[6] > 0 && found[6] < buckets.lists.len() - 1,
            "{found:?}"
        );
    }
}
