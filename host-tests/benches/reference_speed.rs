//! Benchmark of the reference model's two integrators on the paper's cases
//! (docs/reference-speed.md): Case 1 at 60 bar and Case 2, 600 s each,
//! with the multirate fast path (`sim::simulate_fast`) and the BDF plant
//! (`sim::simulate`), outputs every 10 s (Case 1) and every 1 s (Case 2).
//! Prints each run's work counters and the fast path's largest deviation
//! from the BDF at rtol 1e-9 over every node temperature. Then a batch of
//! independent runs (`sim::simulate_batch`, rayon's work-stealing pool) on
//! pools of 1 and 2 threads: 16 Case 1 runs and 4 Case 2 runs of rigs with
//! different outer-convection scales, as a sweep or an uncertainty band
//! would run them. Run with
//! `cargo bench --profile speed -p eha-sim --bench reference_speed`.

use criterion::{criterion_group, criterion_main, Criterion};
use eha_sim::network::NODES;
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::sim::{simulate, simulate_batch, simulate_fast, simulate_rtol, SimOptions, SimOutput, Solver};
use std::hint::black_box;

fn max_dev(a: &SimOutput, b: &SimOutput) -> f64 {
    NODES
        .iter()
        .filter_map(|n| Some((a.get(n.channel())?, b.get(n.channel())?)))
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).abs()))
        .fold(0.0, f64::max)
}

fn reference_speed(c: &mut Criterion) {
    let rig = Rig::default();
    let cases = [
        ("case1_60bar_600s", Scenario::Case1 { needle_bar: 60.0, duration_s: 600.0 }, SimOptions { output_interval_s: 10.0, control_interval_s: 10.0 }),
        ("case2_600s", Scenario::Case2 { duration_s: 600.0 }, SimOptions { output_interval_s: 1.0, control_interval_s: 1.0 }),
    ];
    for (name, sc, opt) in cases {
        let tight = simulate_rtol(&rig, &sc, &opt, 1e-9).expect("runs");
        let fast = simulate_fast(&rig, &sc, &opt).expect("runs");
        let bdf = simulate(&rig, &sc, &opt).expect("runs");
        eprintln!(
            "{name}: fast {} steps, {} model evaluations, {:.2e} K from rtol 1e-9; BDF {} steps, {} evaluations, {:.2e} K",
            fast.stats.steps,
            fast.stats.rhs_evals,
            max_dev(&fast, &tight),
            bdf.stats.steps,
            bdf.stats.rhs_evals,
            max_dev(&bdf, &tight)
        );
        let mut g = c.benchmark_group(name);
        if name.starts_with("case2") {
            g.sample_size(10);
        }
        g.bench_function("fast", |b| b.iter(|| simulate_fast(black_box(&rig), black_box(&sc), &opt).expect("runs")));
        g.bench_function("bdf", |b| b.iter(|| simulate(black_box(&rig), black_box(&sc), &opt).expect("runs")));
        g.finish();
    }
}

fn batch_scaling(c: &mut Criterion) {
    let rigs = |n: usize| -> Vec<Rig> {
        (0..n)
            .map(|k| {
                let mut r = Rig::default();
                r.nuisance.outer_scale = 0.8 + 0.4 * k as f64 / n as f64;
                r
            })
            .collect()
    };
    let batches = [
        ("case1_x16", rigs(16).into_iter().map(|r| (r, Scenario::Case1 { needle_bar: 60.0, duration_s: 600.0 })).collect::<Vec<_>>(), SimOptions { output_interval_s: 10.0, control_interval_s: 10.0 }),
        ("case2_x4", rigs(4).into_iter().map(|r| (r, Scenario::Case2 { duration_s: 600.0 })).collect(), SimOptions { output_interval_s: 1.0, control_interval_s: 1.0 }),
    ];
    let mut g = c.benchmark_group("batch");
    g.sample_size(10);
    for (name, jobs, opt) in &batches {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
            g.bench_function(format!("{name}_fast_{threads}_threads"), |b| {
                b.iter(|| pool.install(|| simulate_batch(black_box(jobs), opt, Solver::Fast)).into_iter().for_each(|r| drop(r.expect("runs"))))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, reference_speed, batch_scaling);
criterion_main!(benches);
