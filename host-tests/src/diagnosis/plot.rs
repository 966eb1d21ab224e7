//! PNG plots of a diagnosis with plotters: measured against simulated
//! temperatures (before and after), and the residuals. Text uses the DejaVu
//! Sans font embedded by the `dejavu` crate through plotters' `ab_glyph`
//! backend, so no system font packages are needed.

use super::analysis::Diagnosis;
use crate::measured::{Channel, MeasuredRun};
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// Registers the embedded DejaVu Sans as plotters' `sans-serif` font (once
/// per process). Must run before any text is drawn.
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is a valid TrueType file; failure is a build bug.
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("embedded DejaVu Sans rejected by ab_glyph"));
    });
}

type PlotResult<T> = Result<T, Box<dyn std::error::Error>>;

fn channels(d: &Diagnosis, run: &MeasuredRun) -> Vec<Channel> {
    Channel::TEMPERATURES
        .into_iter()
        .filter(|c| run.get(*c).is_some_and(|v| v.iter().any(Option::is_some)) && d.series[1].channels.contains_key(c))
        .collect()
}

fn range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = vals.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(0.1);
    (lo - pad, hi + pad)
}

/// Draws one panel per temperature channel into `path`; `f` draws a panel.
fn panels<F>(path: &Path, n: usize, title: &str, mut f: F) -> PlotResult<()>
where
    F: FnMut(usize, &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> PlotResult<()>,
{
    let root = BitMapBackend::new(path, (1100, 260 * n.max(1) as u32 + 40)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 22))?;
    for (k, area) in root.split_evenly((n.max(1), 1)).iter().enumerate().take(n) {
        f(k, area)?;
    }
    root.present()?;
    Ok(())
}

/// Writes `temperatures.png` (measured, calibrated baseline, model with the
/// cause) and `residuals.png` (simulated − measured, before and after) into
/// `out`; returns their file names.
pub fn write_plots(d: &Diagnosis, run: &MeasuredRun, out: &Path) -> PlotResult<Vec<String>> {
    register_fonts();
    let chans = channels(d, run);
    let t = &run.time_s;
    let (t0, t1) = (t[0], t[t.len() - 1]);
    let after_label = format!("with {}", d.cause.name());
    let title = format!("Measured vs simulated (held-out window from {:.0} s)", d.split_time_s);
    panels(&out.join("temperatures.png"), chans.len(), &title, |k, area| {
        let ch = chans[k];
        let m = run.get(ch).unwrap_or(&[]);
        let (b, a) = (&d.series[1].channels[&ch], &d.series[2].channels[&ch]);
        let (lo, hi) = range(m.iter().flatten().copied().chain(b.iter().copied()).chain(a.iter().copied()));
        let mut c = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(60)
            .caption(format!("{} (°C)", ch.name()), ("sans-serif", 16))
            .build_cartesian_2d(t0..t1, lo..hi)?;
        c.configure_mesh().x_desc("time (s)").light_line_style(WHITE).draw()?;
        c.draw_series(LineSeries::new([(d.split_time_s, lo), (d.split_time_s, hi)], BLACK.mix(0.4)))?;
        c.draw_series(t.iter().zip(m).filter_map(|(t, m)| Some(Circle::new((*t, (*m)?), 1, BLACK.mix(0.5).filled()))))?
            .label("measured")
            .legend(|(x, y)| Circle::new((x + 10, y), 3, BLACK.filled()));
        c.draw_series(LineSeries::new(t.iter().copied().zip(b.iter().copied()), RED.stroke_width(2)))?
            .label("calibrated baseline")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
        c.draw_series(LineSeries::new(t.iter().copied().zip(a.iter().copied()), BLUE.stroke_width(2)))?
            .label(after_label.as_str())
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE.stroke_width(2)));
        c.configure_series_labels().position(SeriesLabelPosition::LowerRight).background_style(WHITE.mix(0.8)).border_style(BLACK).draw()?;
        Ok(())
    })?;
    let res = |s: &super::model::SimSeries, ch: Channel| -> Vec<(f64, f64)> {
        let m = run.get(ch).unwrap_or(&[]);
        t.iter().zip(m).zip(&s.channels[&ch]).filter_map(|((t, m), y)| Some((*t, y - (*m)?))).collect()
    };
    panels(&out.join("residuals.png"), chans.len(), "Residuals, simulated − measured (K)", |k, area| {
        let ch = chans[k];
        let (rb, ra) = (res(&d.series[1], ch), res(&d.series[2], ch));
        let (lo, hi) = range(rb.iter().chain(&ra).map(|p| p.1).chain([0.0]));
        let mut c = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(60)
            .caption(format!("{} residual (K)", ch.name()), ("sans-serif", 16))
            .build_cartesian_2d(t0..t1, lo..hi)?;
        c.configure_mesh().x_desc("time (s)").light_line_style(WHITE).draw()?;
        c.draw_series(LineSeries::new([(t0, 0.0), (t1, 0.0)], BLACK.mix(0.4)))?;
        c.draw_series(LineSeries::new([(d.split_time_s, lo), (d.split_time_s, hi)], BLACK.mix(0.4)))?;
        c.draw_series(LineSeries::new(rb, RED.stroke_width(1)))?
            .label("calibrated baseline")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
        c.draw_series(LineSeries::new(ra, BLUE.stroke_width(1)))?
            .label(after_label.as_str())
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE.stroke_width(2)));
        c.configure_series_labels().position(SeriesLabelPosition::LowerRight).background_style(WHITE.mix(0.8)).border_style(BLACK).draw()?;
        Ok(())
    })?;
    Ok(vec!["temperatures.png".into(), "residuals.png".into()])
}
