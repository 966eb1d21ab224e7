//! Benchmark: `eha-sim uq` on Case 1 at 60 bar, 200 Latin-hypercube samples of
//! the paper rig's uncertain parameters in parallel (target:
//! ≤ 5 s on 2 cores). Prints the threads used.

use criterion::{criterion_group, criterion_main, Criterion};
use eha_sim::rig::Rig;
use eha_sim::uq::{run, UqOptions};
use std::hint::black_box;

fn uq_200_case1(c: &mut Criterion) {
    let rig = Rig::default();
    let o = UqOptions { samples: 200, ..UqOptions::default() };
    eprintln!("uq: {} samples of Case 1 at {} bar on {} threads", o.samples, o.needle_bar, rayon::current_num_threads());
    let mut g = c.benchmark_group("uq");
    g.sample_size(10);
    g.bench_function("uq_200_case1_60bar", |b| b.iter(|| run(black_box(&rig), &o, &|| {}).expect("uq runs")));
    g.finish();
}

criterion_group!(benches, uq_200_case1);
criterion_main!(benches);
