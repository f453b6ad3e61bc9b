//! Loads ahead: [`prefetch`] asks the processor to bring a place into the cache and goes on
//! at once. The continuous timeline uses it for what the impacts about to be taken will read
//! (`continuous/prefetch.rs`, the grid's `prefetch_slot`); nothing here changes a result.

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
