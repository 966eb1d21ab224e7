//! What `eha-sim uq` writes (the bands as CSV, the paper checks as a
//! Markdown table, the band plots) and its command line.

use super::*;
use std::path::Path;

/// The bands as CSV: `time_s`, then `<channel>_p05, _p50, _p95, _nominal` per
/// channel (the nominal rig's own run beside the band: the firmware's estimate
/// follows it, `p95 - nominal` is the margin, README).
pub fn bands_csv(uq: &Uq) -> String {
    let mut s = String::from("time_s");
    for (n, _) in &uq.bands {
        s.push_str(&format!(",{n}_p05,{n}_p50,{n}_p95,{n}_nominal"));
    }
    s.push('\n');
    for (i, t) in uq.time_s.iter().enumerate() {
        s.push_str(&format!("{t}"));
        for (n, b) in &uq.bands {
            let [a, m, c] = b[i];
            let nom = uq.nominal.get(n).and_then(|v| v.get(i)).copied().unwrap_or(f64::NAN);
            s.push_str(&format!(",{a:.4},{m:.4},{c:.4},{nom:.4}"));
        }
        s.push('\n');
    }
    s
}

/// The largest `p95 - nominal` of `channel` over the run, K: the margin to take
/// off a threshold on the nominal model's estimate so that the true value of a
/// machine anywhere in the ranges stays below it with 95 % (one-sided).
pub fn upper_margin(uq: &Uq, channel: &str) -> Option<f64> {
    let (_, b) = uq.bands.iter().find(|(n, _)| n == channel)?;
    let nom = uq.nominal.get(channel)?;
    b.iter().zip(nom).map(|(b, n)| b[2] - n).reduce(f64::max)
}

/// The paper checks as a Markdown table.
pub fn checks_markdown(uq: &Uq, samples: usize) -> String {
    checks_table(&uq.checks, samples)
}

/// The paper numbers against their bands as a Markdown table (`samples`:
/// how many the bands came from).
pub fn checks_table(checks: &[PaperCheck], samples: usize) -> String {
    let mut s = format!("| paper number | paper | nominal | 5 % | 50 % | 95 % | 90 % band width | position ({samples} samples) |\n|---|---|---|---|---|---|---|---|\n");
    for c in checks {
        let pos = if c.inside { "inside".to_string() } else { format!("outside by {:+.2} {}", c.outside_by, c.unit) };
        s.push_str(&format!(
            "| {} | {:.2} {u} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} {u} | {pos} |\n",
            c.name,
            c.paper,
            c.nominal,
            c.band[0],
            c.band[1],
            c.band[2],
            c.width,
            u = c.unit
        ));
    }
    s
}

/// Channels drawn in the PNG: (panel label, channels with their legend names).
pub const PLOT: [(&str, &[(&str, &str)]); 3] = [
    ("ports and drain, °C", &[("t_drain_c", "drain"), ("t_outlet_c", "outlet"), ("t_inlet_c", "inlet")]),
    ("metal, °C", &[("t_pump_c", "pump shell"), ("t_block_c", "main block"), ("t_ballvalve_c", "ball-valve block")]),
    ("losses, W", &[("p_total_w", "total")]),
];

/// Writes `bands.csv`, `paper.md`, `paper.json`, `factors.csv` and
/// `bands.png` into `dir`.
pub fn write(dir: &Path, rig: &Rig, uq: &Uq, o: &UqOptions) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    std::fs::write(dir.join("bands.csv"), bands_csv(uq))?;
    std::fs::write(dir.join("paper.md"), checks_markdown(uq, o.samples))?;
    std::fs::write(dir.join("paper.json"), serde_json::to_string_pretty(&uq.checks)?)?;
    let mut f = rig.uncertain.iter().map(|u| u.name.clone()).collect::<Vec<_>>().join(",");
    f.push('\n');
    for row in &uq.factors {
        f.push_str(&row.iter().map(|x| format!("{x:.5}")).collect::<Vec<_>>().join(","));
        f.push('\n');
    }
    std::fs::write(dir.join("factors.csv"), f)?;
    plot_bands(&dir.join("bands.png"), &format!("Case 1 at {} bar: 5-95 % bands over {} samples of the uncertain parameters", o.needle_bar, o.samples), uq)
}

/// The PNG: [`PLOT`]'s channels, each band shaded with its median drawn, the
/// nominal dashed, Table 4's values marked at 600 s.
pub fn plot_bands(path: &Path, title: &str, uq: &Uq) -> Result<()> {
    use plotters::prelude::*;
    crate::plot::font()?;
    let err = |e: &dyn std::fmt::Display| anyhow!("plotting {}: {e}", path.display());
    let root = BitMapBackend::new(path, (1200, 80 + 380 * PLOT.len() as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(|e| err(&e))?;
    let colors = [BLUE, RED, RGBColor(0, 140, 0)];
    let table4 = [("t_drain_c", 59.67), ("t_outlet_c", 54.17), ("t_inlet_c", 53.00), ("t_pump_c", 25.38)];
    for ((label, chans), area) in PLOT.iter().zip(root.split_evenly((PLOT.len(), 1)).iter()) {
        let band = |c: &str| uq.bands.iter().find(|(n, _)| n == c).map(|(_, b)| b.as_slice());
        // (the range from 5 s on: the losses start from rest)
        let (mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY);
        for (c, _) in chans.iter() {
            for b in band(c).unwrap_or(&[]).iter().skip(5) {
                y0 = y0.min(b[0]);
                y1 = y1.max(b[2]);
            }
        }
        if !(y0.is_finite() && y1 > y0) {
            continue;
        }
        let pad = (y1 - y0) * 0.05;
        let t1 = uq.time_s.last().copied().unwrap_or(1.0);
        let mut ch = ChartBuilder::on(area)
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(0.0..t1, (y0 - pad)..(y1 + pad))
            .map_err(|e| err(&e))?;
        ch.configure_mesh().x_desc("time, s").y_desc(*label).draw().map_err(|e| err(&e))?;
        for (i, (c, legend)) in chans.iter().enumerate() {
            let Some(b) = band(c) else { continue };
            let col = colors[i % colors.len()];
            let mut poly: Vec<(f64, f64)> = uq.time_s.iter().zip(b).map(|(t, b)| (*t, b[2])).collect();
            poly.extend(uq.time_s.iter().zip(b).rev().map(|(t, b)| (*t, b[0])));
            ch.draw_series(std::iter::once(Polygon::new(poly, col.mix(0.2).filled()))).map_err(|e| err(&e))?;
            ch.draw_series(LineSeries::new(uq.time_s.iter().zip(b).map(|(t, b)| (*t, b[1])), col.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(format!("{legend} (median, 5-95 % shaded)"))
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2)));
            if let Some(nom) = uq.nominal.get(c) {
                ch.draw_series(DashedLineSeries::new(uq.time_s.iter().copied().zip(nom.iter().copied()), 6, 4, col.stroke_width(1))).map_err(|e| err(&e))?;
            }
            if let Some((_, v)) = table4.iter().find(|(n, _)| n == c) {
                ch.draw_series(std::iter::once(Cross::new((DURATION_S.min(t1), *v), 8, BLACK.stroke_width(2))))
                    .map_err(|e| err(&e))?;
            }
        }
        ch.configure_series_labels().position(SeriesLabelPosition::UpperLeft).background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// Arguments of `eha-sim uq`.
#[derive(Debug, Clone, clap::Args)]
pub struct UqArgs {
    /// Rig file (TOML with `[[uncertain]]`); default the paper rig.
    #[arg(long)]
    pub rig: Option<std::path::PathBuf>,
    /// Number of samples (Latin hypercube).
    #[arg(long, default_value_t = 200)]
    pub samples: usize,
    /// Seed of the Latin hypercube.
    #[arg(long, default_value_t = 34)]
    pub seed: u64,
    /// Needle setting of Case 1, bar.
    #[arg(long, default_value_t = 60.0)]
    pub needle_bar: f64,
    /// Also Table 5 with ram air (15, 30, 50 m/s: three more runs per sample).
    #[arg(long)]
    pub table5: bool,
    /// Output directory.
    #[arg(long, default_value = "out/uq")]
    pub out: std::path::PathBuf,
}

/// `eha-sim uq`.
pub fn run_cli(a: &UqArgs) -> Result<()> {
    let rig = match &a.rig {
        Some(p) => Rig::from_toml_file(p)?,
        None => Rig::default(),
    };
    let o = UqOptions { samples: a.samples, seed: a.seed, needle_bar: a.needle_bar, table5: a.table5 };
    let bar = indicatif::ProgressBar::new(o.samples as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} samples {elapsed} (eta {eta})").unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let t = std::time::Instant::now();
    let uq = run(&rig, &o, &|| bar.inc(1))?;
    bar.finish_and_clear();
    write(&a.out, &rig, &uq, &o)?;
    println!("{} samples of {} uncertain groups in {:.1} s ({} threads)", o.samples, rig.uncertain.len(), t.elapsed().as_secs_f64(), rayon::current_num_threads());
    print!("{}", checks_markdown(&uq, o.samples));
    if let Some(m) = upper_margin(&uq, "t_drain_c") {
        println!("drain: 95 % above the nominal by at most {m:.2} K over the run (the valve-threshold margin, README)");
    }
    println!("wrote {}", a.out.display());
    Ok(())
}
