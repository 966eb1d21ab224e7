//! PNG plot of a PIL run: reference (true) drain temperature and the
//! firmware's prediction over time, the 40 °C valve threshold, and the LNG
//! valve command below. Pure Rust (plotters + an embedded DejaVu font), so it
//! needs nothing installed on the machine.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};
use plotters::prelude::*;

use super::TickRecord;

use crate::plot::font;

/// Write the plot to `path` (PNG). Returns its path.
pub fn plot_if_available(records: &[TickRecord], path: &Path) -> Result<Option<PathBuf>> {
    if records.len() < 2 {
        return Ok(None);
    }
    font()?;
    let err = |e: &dyn std::fmt::Display| anyhow!("plotting {}: {e}", path.display());
    let root = BitMapBackend::new(path, (1200, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (top, bottom) = root.split_vertically(620);
    let t_end = records.last().map_or(1.0, |r| r.t_s);
    // Plot at most ~4000 points per series.
    let stride = (records.len() / 4000).max(1);
    let pts = || records.iter().step_by(stride);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for r in pts() {
        for v in [r.sensors.t_drain_c, f64::from(r.reply.out.drain_c)] {
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
    }
    lo = (lo.min(40.0) - 2.0).floor();
    hi = (hi.max(40.0) + 2.0).ceil();
    let mut c = ChartBuilder::on(&top)
        .caption("EHA drain oil: reference plant vs firmware prediction (PIL, QEMU)", ("sans-serif", 24))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_end, lo..hi)
        .map_err(|e| err(&e))?;
    c.configure_mesh().x_desc("time, s").y_desc("drain temperature, °C").draw().map_err(|e| err(&e))?;
    c.draw_series(LineSeries::new(pts().map(|r| (r.t_s, r.sensors.t_drain_c)), BLUE.stroke_width(2)))
        .map_err(|e| err(&e))?
        .label("reference (true) drain")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE.stroke_width(2)));
    c.draw_series(LineSeries::new(pts().map(|r| (r.t_s, f64::from(r.reply.out.drain_c))), RED.stroke_width(2)))
        .map_err(|e| err(&e))?
        .label("firmware prediction")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
    c.draw_series(LineSeries::new([(0.0, 40.0), (t_end, 40.0)], RGBColor(80, 80, 80).stroke_width(2)))
        .map_err(|e| err(&e))?
        .label("valve threshold 40 °C")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RGBColor(80, 80, 80).stroke_width(2)));
    c.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).position(SeriesLabelPosition::LowerRight).draw().map_err(|e| err(&e))?;

    let mut v = ChartBuilder::on(&bottom)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_end, -0.1..1.1)
        .map_err(|e| err(&e))?;
    v.configure_mesh().x_desc("time, s").y_desc("LNG valve").y_labels(2).draw().map_err(|e| err(&e))?;
    // Step plot of the valve command: exact change points only.
    let valve = |r: &TickRecord| if r.reply.out.valve_open { 1.0 } else { 0.0 };
    let mut steps = Vec::new();
    let mut prev = records.first().map_or(0.0, valve);
    steps.push((0.0, prev));
    for r in records {
        let y = valve(r);
        if y != prev {
            steps.push((r.t_s, prev));
            steps.push((r.t_s, y));
            prev = y;
        }
    }
    steps.push((t_end, prev));
    v.draw_series(LineSeries::new(steps, GREEN.stroke_width(2))).map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(Some(path.to_path_buf()))
}
