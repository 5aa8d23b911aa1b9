//! Wall time of the batched Hrovat & Tobler steady state in pure Rust (the `bench/` inputs:
//! Appendix D, pump 100–400 rad/s, SR 0–1): `cargo run --release --example steady_timing [N]`.
use std::time::Instant;

use tcsim_core::batch::ht_steady_states;
use tcsim_core::converter::hrovat_tobler::HtGeometry;

fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    // a fixed pseudo-random sequence (xorshift), no dependency
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let wp: Vec<f64> = (0..n).map(|_| 100.0 + 300.0 * uniform()).collect();
    let wt: Vec<f64> = wp.iter().map(|w| w * uniform()).collect();
    let g = [HtGeometry::appendix_d()];
    let mut times = Vec::new();
    for _ in 0..7 {
        let start = Instant::now();
        let out = ht_steady_states(&g, &wp, &wt, true).unwrap();
        times.push(start.elapsed().as_secs_f64());
        assert_eq!(out.flow_m3_s.len(), n);
    }
    times.sort_by(f64::total_cmp);
    println!("{n} points: median {:.1} ns/point, fastest {:.1}", 1e9 * times[3] / n as f64, 1e9 * times[0] / n as f64);
}
