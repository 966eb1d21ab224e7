//! Benchmark: Case 1 at 60 bar, 600 s, the full model (issue acceptance:
//! aim ≤ 5 ms). Prints the right-hand-side evaluations of one run.

use criterion::{criterion_group, criterion_main, Criterion};
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::sim::{simulate, SimOptions};
use std::hint::black_box;

fn case1_60bar(c: &mut Criterion) {
    let rig = Rig::default();
    let sc = Scenario::Case1 { needle_bar: 60.0, duration_s: 600.0 };
    let opt = SimOptions { output_interval_s: 10.0, control_interval_s: 10.0 };
    let out = simulate(&rig, &sc, &opt).expect("runs");
    eprintln!("case1 60 bar 600 s: {} rhs evaluations, {} BDF steps", out.stats.rhs_evals, out.stats.steps);
    c.bench_function("case1_60bar_600s", |b| b.iter(|| simulate(black_box(&rig), black_box(&sc), &opt).expect("runs")));
    let sc2 = Scenario::Case2 { duration_s: 600.0 };
    let opt2 = SimOptions { output_interval_s: 1.0, control_interval_s: 1.0 };
    let out2 = simulate(&rig, &sc2, &opt2).expect("runs");
    eprintln!("case2 600 s: {} rhs evaluations, {} BDF steps", out2.stats.rhs_evals, out2.stats.steps);
    let mut g = c.benchmark_group("slow");
    g.sample_size(10);
    g.bench_function("case2_600s", |b| b.iter(|| simulate(black_box(&rig), black_box(&sc2), &opt2).expect("runs")));
    g.finish();
}

criterion_group!(benches, case1_60bar);
criterion_main!(benches);
