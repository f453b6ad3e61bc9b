//! Loads ahead: [`prefetch`] asks the processor to bring a place into the cache and goes on
//! at once. The continuous timeline uses it for what the impacts about to be taken will read
//! (`continuous/prefetch.rs`, the grid's `prefetch_slot`), the discrete response for the
//! balls of the contacts to come (`geometry/impulse.rs`); nothing here changes a result.

/// Below this many balls the arrays a step reads mostly fit the cache, and loading ahead only
/// costs: measured for both users, 1–3% at 1,000 and 10,000 balls (four rounds each), where
/// from 30,000 on the continuous timeline gains (docs/performance.md, *Prefetching the coming
/// impacts*).
pub const PREFETCH_MIN_BALLS: usize = 20_000;

/// Starts bringing the cache line that holds `place` into every level of the cache, without
/// waiting for it: unlike a load, the instruction is done at once, so the misses of several
/// places ahead overlap with each other and with the work before them. Where there is no
/// such instruction (other than x86-64), a plain load whose value goes to
/// [`black_box`](std::hint::black_box), which the processor also starts at once but must
/// see done before it retires.
#[inline(always)]
pub fn prefetch<T: Copy>(place: Option<&T>) {
    let Some(place) = place else { return };
    #[cfg(target_arch = "x86_64")]
    safe_arch::prefetch_t0(place);
    #[cfg(not(target_arch = "x86_64"))]
    std::hint::black_box(*place);
}
