//! Probe (docs/performance.md, thirtieth session): the time of an `in_pieces` pass of 25
//! pieces of almost no work on two threads, what handing out a pass costs. To run it:
//!   mkdir -p examples && cp docs/experiments/pass_overhead.rs examples/
//!   cargo build --release --example pass_overhead && target/release/examples/pass_overhead
use ballpit::sim::parallel::in_pieces;
use std::time::Instant;

fn main() {
    bevy::tasks::ComputeTaskPool::get_or_init(|| {
        bevy::tasks::TaskPoolBuilder::new().num_threads(1).build()
    });
    let mut data = vec![1u64; 25 * 4096];
    for round in 0..5 {
        let t = Instant::now();
        let n = 20_000;
        for _ in 0..n {
            let sums = in_pieces(data.chunks_mut(4096), true, |piece| {
                piece[0] += 1;
                piece[0]
            });
            std::hint::black_box(sums);
        }
        println!("round {round}: {:.2} us a pass", t.elapsed().as_secs_f64() * 1e6 / n as f64);
    }
}
