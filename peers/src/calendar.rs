//! The persistent timeline's event queue (`edmd.rs`): a calendar queue, buckets of time in a
//! ring, each a plain list until its turn and then a binary heap.

use std::collections::BinaryHeap;

use crate::edmd::Event;

/// Buckets of time in a ring of `RING`, each a plain list until its turn, then a heap; events
/// past the ring wait in `far` until it comes round. Pops in the order one heap would.
pub struct Calendar {
    width: f64,
    ring: Vec<Vec<Event>>,
    current: BinaryHeap<Event>,
    /// The bucket `current` holds (and every earlier one, emptied).
    at: u64,
    far: Vec<Event>,
}

const RING: u64 = 4096;

impl Calendar {
    /// An empty queue whose buckets span `width` seconds each.
    pub fn new(width: f64) -> Self {
        Calendar {
            width,
            ring: (0..RING).map(|_| Vec::new()).collect(),
            current: BinaryHeap::new(),
            at: 0,
            far: Vec::new(),
        }
    }

    fn bucket(&self, time: f64) -> u64 {
        (time / self.width) as u64
    }

    pub fn push(&mut self, event: Event) {
        let bucket = self.bucket(event.time);
        if bucket <= self.at {
            self.current.push(event);
        } else if bucket < self.at + RING {
            self.ring[(bucket % RING) as usize].push(event);
        } else {
            self.far.push(event);
        }
    }

    /// The earliest event, if it comes by `end`. A bucket's events that are no longer
    /// `is_current` are dropped when its turn comes, before they are heaped.
    pub fn pop_until(&mut self, end: f64, is_current: impl Fn(&Event) -> bool) -> Option<Event> {
        loop {
            if let Some(top) = self.current.peek() {
                return if top.time <= end {
                    self.current.pop()
                } else {
                    None
                };
            }
            if self.at >= self.bucket(end) {
                return None;
            }
            self.at += 1;
            if self.at.is_multiple_of(RING) {
                let far = std::mem::take(&mut self.far);
                for event in far.into_iter().filter(&is_current) {
                    self.push(event);
                }
            }
            // The bucket's events join the heap (empty, or holding the far events that fell in
            // this very bucket); the bucket keeps its buffer.
            let mut heap = std::mem::take(&mut self.current).into_vec();
            let bucket = &mut self.ring[(self.at % RING) as usize];
            heap.extend(bucket.drain(..).filter(&is_current));
            self.current = BinaryHeap::from(heap);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator (no dependency for one test).
    fn next(state: &mut u64) -> u64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *state >> 33
    }

    #[test]
    fn the_calendar_gives_what_one_heap_gives_across_wraps_and_far_events() {
        // Buckets of 1 ms: the ring spans 4.096 s, and some events lie further off.
        let mut calendar = Calendar::new(1e-3);
        let mut heap = BinaryHeap::new();
        let (mut state, mut now) = (7_u64, 0.0_f64);
        let mut popped = 0;
        for step in 0..400 {
            // New events from now on: most soon, some seconds away (past the ring), some in
            // the very bucket where the ring next comes round after it (held as far ones).
            let ring_span = RING as f64 * 1e-3;
            let round = ((now / ring_span).floor() + 2.0) * ring_span + 0.5e-3;
            for k in 0..50 {
                let soon = 0.05 * (next(&mut state) % 1000) as f64 / 1000.0;
                let time = match k % 10 {
                    0 => now + 9.0 * soon / 0.05,
                    1 => round,
                    _ => now + soon,
                };
                let event = Event {
                    time,
                    ball: (next(&mut state) % 100) as u32,
                    other: k,
                    count: 0,
                    other_count: 0,
                };
                calendar.push(event);
                heap.push(event);
            }
            let end = now + 0.02 + (step % 3) as f64 * 0.01;
            while let Some(event) = calendar.pop_until(end, |_| true) {
                assert_eq!(Some(event), heap.pop(), "pop {popped}");
                popped += 1;
            }
            assert!(heap.peek().is_none_or(|event| event.time > end));
            now = end;
        }
        assert!(popped > 15_000, "{popped}");
    }
}
