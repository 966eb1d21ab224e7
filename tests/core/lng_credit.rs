//! The LNG exchanger's cooling credit: only when the cooling is real
//! (issue "No silent protection failure", item 2).

use eha_guard::model::{Model, ModelInputN, HBAR_PER_BAR, HRADS_PER_RPM};
use eha_guard::num::{Fx, Num};
use eha_guard::params::{DEFAULT, N_TABLE, TICKS_PER_STEP};

/// Flow at the LNG table's second point, L/s: `q_max / (N_TABLE - 1)^2` =
/// 1.98e-3 L/s, the pump's geometric flow at 6.2 rpm.
fn q1_lps() -> f64 {
    DEFAULT.flow_table_max_m3_per_s * 1e3 / ((N_TABLE - 1) * (N_TABLE - 1)) as f64
}

fn input<N: Num>(p_a_bar: f64, rpm: f64) -> ModelInputN<N> {
    let f = N::from_f64;
    ModelInputN {
        current_ha: N::ZERO,
        p_a_hbar: f(p_a_bar * HBAR_PER_BAR),
        p_b_hbar: f(5.0 * HBAR_PER_BAR),
        speed_hrads: f(rpm * HRADS_PER_RPM),
        dpos_mm: N::ZERO,
        ambient_c: f(20.0),
    }
}

/// Model at the state of the reference LNG run just before its pump stops (drain 38.7,
/// loop 19.8 degC, exchanger open), 10 s at 60 bar / 500 rpm with the exchanger open,
/// then the pump stopped with the ports decaying from 30 to 5 bar over 3 s (as the
/// reference's do) and the exchanger still commanded open. Returns, per model step
/// after the stop: (pump flow L/s, LNG credit kW, links, nodes).
fn stop_with_valve_open<N: Num>() -> Vec<(f64, f64, [f64; 3], [f64; 6])> {
    let mut m = Model::<N>::new(&DEFAULT).expect("model");
    m.set_temperatures(&[18.1, 38.7, 19.8, 17.2, 16.7, 16.0], 20.0);
    for _ in 0..100 {
        m.step(&input::<N>(65.0, 500.0), true);
    }
    let mut out = vec![];
    for s in 0..100u32 {
        let t = s as f64 * TICKS_PER_STEP as f64 * 0.01;
        let p = 5.0 + 25.0 * (-t / 1.0).exp();
        m.step(&input::<N>(p, 0.0), true);
        let q = DEFAULT.k_leak_m3_per_s_pa * (p - 5.0) * 1e5 * 1e3;
        let f = |x: &[N]| x.iter().map(|v| v.to_f64()).collect::<Vec<_>>();
        let l = f(&m.links_c());
        let n = f(&m.temperatures_c());
        out.push((q, m.last_lng_kw().to_f64(), [l[0], l[1], l[2]], [n[0], n[1], n[2], n[3], n[4], n[5]]));
    }
    out
}

#[test]
fn stopped_pump_gets_no_exchanger_credit_and_keeps_its_links_physical() {
    // With the pump stopped the only oil through the exchanger is the ports'
    // leakage (≤ 8e-4 L/s, below the table's second point 1.98e-3 L/s). Before: the
    // table's first interval (linear in sqrt(q)) credited 0.38 kW to a stream carrying
    // about 1 W/K, the quasi-steady links went to -280 degC (120 K below the LNG
    // itself) and the case oil, fed by that leakage, fell 0.7 K below the reference
    // within 3 s (closed-loop LNG run with the pump stopped at 300 s,
    // `host-tests/tests/firmware`). Now: no credit below the second table point (hot
    // side: the few watts the real exchanger takes from a stream that slow are not
    // credited), and no link is colder than the LNG inlet.
    for (name, run) in [("f64", stop_with_valve_open::<f64>()), ("f32", stop_with_valve_open::<f32>()), ("Fx", stop_with_valve_open::<Fx>())] {
        for (s, (q, lng, links, _)) in run.iter().enumerate() {
            assert!(*q < q1_lps(), "{name} step {s}: leakage {q} L/s not below the table's second point {}", q1_lps());
            assert_eq!(*lng, 0.0, "{name} step {s}: {lng} kW credited with the pump stopped");
            for l in links {
                assert!(*l >= DEFAULT.lng_inlet_c, "{name} step {s}: link {l} degC colder than the LNG inlet {} degC", DEFAULT.lng_inlet_c);
            }
        }
    }
}
