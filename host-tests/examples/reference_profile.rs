//! Work counters of the reference model's two integrators on Case 1 (60 bar)
//! and Case 2, 600 s each, with the benchmark's outputs: steps, model
//! evaluations (and how many built Jacobians), Newton iterations and
//! factorisations, and for the fast path its hydraulic steps. The profile
//! of `docs/reference-speed.md` runs this binary under
//! `valgrind --tool=callgrind` (one case per run: `1` or `2`, both without
//! an argument).
//!
//! `cargo run --profile fast -p eha-sim --example reference_profile -- 2`
//! (the counters; instruction counts are taken of the `speed` profile's
//! binary, `target/speed/examples/reference_profile`: eha-sim in one
//! codegen unit, the same inlining whatever else changes)
//!
//! `DURATION_S=5` runs the fast path over the first 5 s only (the same
//! plant and callbacks, ending there): where a run's work goes in time.
//!
//! `BENCH_ITERS=n` runs `sim::simulate_fast` n times per case instead, as
//! one criterion iteration of `benches/reference_speed.rs` runs it (the
//! plant's construction, its run and the output's assembly): callgrind with
//! `--toggle-collect='*simulate_fast*'` counts what the bench times, and
//! n = 1 against n = 2 separates the first run in a process (which fills
//! the per-thread memos) from the later ones the bench repeats.

use eha_sim::fast::{FastOptions, FastPlant};
use eha_sim::rig::Rig;
use eha_sim::scenario::Scenario;
use eha_sim::sim::{simulate, simulate_fast, SimOptions};

fn main() {
    let which = std::env::args().nth(1);
    let rig = Rig::default();
    let cases = [
        ("1", Scenario::Case1 { needle_bar: 60.0, duration_s: 600.0 }, SimOptions { output_interval_s: 10.0, control_interval_s: 10.0 }),
        ("2", Scenario::Case2 { duration_s: 600.0 }, SimOptions { output_interval_s: 1.0, control_interval_s: 1.0 }),
    ];
    let fast_only = std::env::var_os("FAST_ONLY").is_some();
    let bdf_only = std::env::var_os("BDF_ONLY").is_some();
    let duration: Option<f64> = std::env::var("DURATION_S").ok().map(|s| s.parse().expect("DURATION_S: seconds"));
    let bench_iters: Option<usize> = std::env::var("BENCH_ITERS").ok().map(|s| s.parse().expect("BENCH_ITERS: a count"));
    for (key, sc, opt) in cases {
        if which.as_deref().is_some_and(|w| w != key) {
            continue;
        }
        if let Some(n) = bench_iters {
            for _ in 0..n {
                let out = simulate_fast(std::hint::black_box(&rig), std::hint::black_box(&sc), &opt).expect("runs");
                std::hint::black_box(&out);
            }
            println!("case {key}: simulate_fast run {n} times");
            continue;
        }
        if !fast_only {
            let s = simulate(&rig, &sc, &opt).expect("BDF runs").stats;
            println!(
                "case {key} BDF: {} steps, {} model evaluations ({} for Jacobian columns), {} Newton iterations, {} factorisations",
                s.steps, s.rhs_evals, s.jacobian_evals, s.newton_iterations, s.factorizations
            );
        }
        if !bdf_only {
            // The plant itself (the same steps as `simulate_fast`, whose
            // callbacks only read the interpolants), for its own counters.
            let mut p = FastPlant::with_options(&rig, &sc, FastOptions::for_scenario(&sc)).expect("plant");
            let t_end = duration.unwrap_or(sc.duration_s());
            p.run(opt.control_interval_s.min(opt.output_interval_s), t_end, |_| Ok(Default::default())).expect("runs");
            let (s, f) = (p.stats(), p.fast_stats());
            println!(
                "case {key} fast: {} thermal steps ({} rejected), {} model evaluations ({} for {} Jacobians, {} drift refreshes), {} hydraulic steps ({} rejected, {} hydraulic evaluations, {} Jacobians)",
                s.steps, f.rejected, s.rhs_evals, s.jacobian_evals, s.factorizations, f.drifts, f.hydraulics.steps, f.hydraulics.rejected, f.hydraulics.evals, f.hydraulics.jacobians
            );
            let (outer, nu) = p.model().grid_evals();
            println!("case {key} fast: exact evaluations behind the temperature grids: {outer} outer-surface heat flows, {nu} viscosities");
        }
    }
}
