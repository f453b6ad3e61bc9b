//! Loads ahead: [`prefetch`] asks the processor to bring a place into the cache and goes on
//! at once. The continuous timeline uses it for what the impacts about to be taken will read
//! (`continuous/prefetch.rs`, the grid's `prefetch_slot`), the discrete response for the
//! balls of the contacts to come (`geometry/impulse.rs`), the grid's counting sort and gather
//! for a great many balls (`geometry/grid/`); nothing here changes a result.

/// Below this many balls the arrays a step reads mostly fit the cache, and loading ahead only
/// costs: measured for both users, 1–3% at 1,000 and 10,000 balls (four rounds each), where
/// from 30,000 on the continuous timeline gains (docs/performance.md, *Prefetching the coming
/// impacts*).
pub const PREFETCH_MIN_BALLS: usize = 20_000;

/// From this many balls the grid's per-ball arrays outgrow this host's 32 MB last-level cache,
/// and its passes that reach into them by index load [`BALLS_AHEAD`] balls ahead. The balls are
/// stored in space order (`scene/build.rs`), so those passes mostly walk forward; but each ball
/// that changed rows of cells since it was stored is a jump the processor's own stream
/// detection does not foresee. Discrete mode, one thread, rounds in turn: a million balls 1–5%
/// quicker in every round, 200,000 and 300,000 about 2%; 100,000, where the arrays still fit
/// the cache, 3.5% slower when loading ahead too (docs/performance.md, *The grid's passes by
/// index loaded ahead (thirty-fifth session)*). From this many balls too, the discrete
/// response's loads ahead take both lines of a circle that straddles two ([`prefetch_whole`]).
pub const FAR_PREFETCH_MIN_BALLS: usize = 200_000;

/// How many balls ahead a pass by index loads, from [`FAR_PREFETCH_MIN_BALLS`] balls: at a
/// million, 64 to 256 measured alike; 32 gained less and 8 was slower than not loading.
pub const BALLS_AHEAD: usize = 128;

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

/// [`prefetch`] for a value that may straddle two cache lines (a 24-byte circle in an array
/// starts at every multiple of 8 within a line, and a quarter of them end in the next): loads
/// the lines of its first and last bytes.
#[inline(always)]
pub fn prefetch_whole<T: bytemuck::Pod>(place: Option<&T>) {
    prefetch(place);
    prefetch(place.and_then(|place| bytemuck::bytes_of(place).last()));
}

/// The size of a cache line on the machines this runs on (x86-64 and most ARM).
const LINE: usize = 64;

/// [`prefetch`] for every cache line that `values` spans, each once: a prefetch for each
/// value, or every other one, asks again for lines already on their way, and at a million
/// balls the prefetches themselves wait for room among the misses in flight.
#[inline(always)]
pub fn prefetch_lines<T: bytemuck::Pod>(values: &[T]) {
    let bytes: &[u8] = bytemuck::cast_slice(values);
    for offset in one_byte_a_line(bytes.as_ptr() as usize, bytes.len()) {
        prefetch(bytes.get(offset));
    }
}

/// Where, in `len` bytes from `address`, one byte of each cache line they span lies: the first
/// byte, then the first of each line after it.
#[inline(always)]
fn one_byte_a_line(address: usize, len: usize) -> impl Iterator<Item = usize> {
    let next_line = LINE - address % LINE;
    let first = (len > 0).then_some(0);
    first.into_iter().chain((next_line..len).step_by(LINE))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_line_a_run_of_bytes_spans_is_loaded_once() {
        for address in [0, 1, 8, 40, 63, 64, 100, 4096 + 24] {
            for len in 0..300 {
                let lines: Vec<usize> = one_byte_a_line(address, len)
                    .map(|offset| {
                        assert!(offset < len, "{offset} past {len} bytes");
                        (address + offset) / LINE
                    })
                    .collect();
                let spanned: Vec<usize> = if len == 0 {
                    Vec::new()
                } else {
                    (address / LINE..=(address + len - 1) / LINE).collect()
                };
                assert_eq!(lines, spanned, "{len} bytes from {address}");
            }
        }
    }
}
