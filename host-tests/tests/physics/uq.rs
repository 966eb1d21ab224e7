//! Uncertainty bands (`eha-sim uq`): the paper's numbers
//! against the 90 % bands of 200 Latin-hypercube samples of the rig's
//! documented uncertain parameters (`[[uncertain]]`, docs/calibration.md),
//! Table 5 with ram air included.

use eha_sim::rig::Rig;
use eha_sim::uq::{latin_hypercube, run, upper_margin, UqOptions, PAPER_NUMBERS};

/// One point per stratum in every dimension.
#[test]
fn latin_hypercube_has_one_point_per_stratum() {
    let n = 50;
    let pts = latin_hypercube(n, 4, 7);
    for d in 0..4 {
        let mut seen = vec![false; n];
        for p in &pts {
            let k = (p[d] * n as f64).floor() as usize;
            assert!(!seen[k], "dimension {d}: stratum {k} twice");
            seen[k] = true;
        }
    }
}

/// Each paper number's position against its 90 % band, as measured (200
/// samples, seed 34, the paper rig; ±0.05 in the number's unit on the
/// distance outside, the inside/outside verdict exact). Measured:
///
/// | number | paper | 5 % … 95 % | position |
/// |---|---|---|---|
/// | Table 4 inlet / outlet / drain | 53.00 / 54.17 / 59.67 °C | 50.47…56.40 / 51.97…57.95 / 56.67…64.35 | inside (fitted to them) |
/// | Table 5 shell, still air | 25.38 °C | 28.08…31.08 | outside by −2.70 K |
/// | Fig. 15 valve opening | 110 s | 95.8…123.8 s | inside (fitted) |
/// | LNG volume, 680 s | 2.30 L | 2.46…2.62 L | outside by −0.16 L |
/// | Table 5 shell 15 / 30 / 50 m/s | 24.78 / 24.32 / 23.82 °C | 26.06…28.88 / 24.72…27.49 / 23.45…26.02 | outside by −1.28 / −0.40 K, inside |
/// | Table 5 drain 15 / 30 / 50 m/s | 59.14 / 58.84 / 58.57 °C | 56.15…63.84 / 55.85…63.51 / 55.31…63.18 | inside |
/// | shell fall 0 → 50 m/s | 1.56 K | 4.16…5.80 K | outside by −2.60 K |
///
/// The still-air shell, its fall under ram air and the LNG volume lie
/// outside what the documented ranges can explain: structural misses of the
/// model (docs/calibration.md), not parameter uncertainty.
#[test]
fn paper_numbers_against_their_90_percent_bands_as_measured() {
    let t = std::time::Instant::now();
    let uq = run(&Rig::default(), &UqOptions { table5: true, ..UqOptions::default() }, &|| {}).expect("uq runs");
    println!("200 samples with Table 5 in {:.2} s", t.elapsed().as_secs_f64());
    let measured: [(&str, Option<f64>); 13] = [
        ("Table 4 inlet", None),
        ("Table 4 outlet", None),
        ("Table 4 drain", None),
        ("Table 5 shell, still air", Some(-2.70)),
        ("Fig. 15 valve opening (oil at 40 °C)", None),
        ("LNG volume for 680 s (eqs. 23-25)", Some(-0.16)),
        ("Table 5 shell 15 m/s", Some(-1.28)),
        ("Table 5 shell 30 m/s", Some(-0.40)),
        ("Table 5 shell 50 m/s", None),
        ("Table 5 drain 15 m/s", None),
        ("Table 5 drain 30 m/s", None),
        ("Table 5 drain 50 m/s", None),
        ("Table 5 shell fall 0 -> 50 m/s", Some(-2.60)),
    ];
    assert_eq!(uq.checks.len(), PAPER_NUMBERS.len());
    let mut failures = vec![];
    for (c, (name, outside)) in uq.checks.iter().zip(measured) {
        assert_eq!(c.name, name);
        println!(
            "{:40} paper {:8.2} {u:2} band {:8.2} {:8.2} {:8.2} width {:6.2} {}",
            c.name,
            c.paper,
            c.band[0],
            c.band[1],
            c.band[2],
            c.width,
            if c.inside { "inside".to_string() } else { format!("outside by {:+.3}", c.outside_by) },
            u = c.unit
        );
        let ok = match outside {
            None => c.inside,
            Some(d) => !c.inside && (c.outside_by - d).abs() <= 0.05,
        };
        if !ok {
            failures.push(format!("{name}: inside {} outside_by {:+.3}, measured {outside:?}: re-measure", c.inside, c.outside_by));
        }
    }
    // The README's valve-threshold margin: the drain's 95 % above the nominal
    // run, at most 4.77 K over the 600 s (measured; ±0.05 K).
    let m = upper_margin(&uq, "t_drain_c").expect("drain band");
    println!("drain margin (95 % - nominal, max over the run) {m:.3} K");
    if (m - 4.77).abs() > 0.05 {
        failures.push(format!("drain margin {m:.3} K, measured 4.77: re-measure"));
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
