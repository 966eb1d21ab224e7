//! Generic multi-panel line plots to PNG (plotters with the embedded DejaVu
//! font, so nothing needs installing).

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::path::Path;

/// Register the embedded font once (plotters' `ab_glyph` backend has no
/// system fonts).
pub fn font() -> Result<()> {
    static ONCE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *ONCE.get_or_init(|| register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular()).is_ok());
    if ok {
        Ok(())
    } else {
        Err(anyhow!("could not load the embedded DejaVu Sans font"))
    }
}

/// One panel: a y-axis label and named series of (x, y) points.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Y-axis label with unit.
    pub y_label: String,
    /// Named series.
    pub series: Vec<(String, Vec<(f64, f64)>)>,
}

const COLORS: [RGBColor; 8] = [BLUE, RED, GREEN, MAGENTA, CYAN, BLACK, RGBColor(255, 140, 0), RGBColor(128, 0, 128)];

/// Draw `panels` stacked vertically against a shared x axis (time, s).
pub fn lines(path: &Path, title: &str, panels: &[Panel]) -> Result<()> {
    font()?;
    let err = |e: &dyn std::fmt::Display| anyhow!("plotting {}: {e}", path.display());
    let height = 80 + 380 * panels.len() as u32;
    let root = BitMapBackend::new(path, (1200, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root.titled(title, ("sans-serif", 24)).map_err(|e| err(&e))?;
    let areas = root.split_evenly((panels.len().max(1), 1));
    for (panel, area) in panels.iter().zip(areas.iter()) {
        let pts = panel.series.iter().flat_map(|(_, s)| s.iter()).filter(|p| p.0.is_finite() && p.1.is_finite());
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for p in pts {
            x0 = x0.min(p.0);
            x1 = x1.max(p.0);
            y0 = y0.min(p.1);
            y1 = y1.max(p.1);
        }
        if x0.is_nan() || x1.is_nan() || x0 >= x1 {
            continue;
        }
        let pad = ((y1 - y0) * 0.05).max(0.5);
        let mut c = ChartBuilder::on(area)
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
            .map_err(|e| err(&e))?;
        c.configure_mesh().x_desc("time, s").y_desc(panel.y_label.as_str()).draw().map_err(|e| err(&e))?;
        for (i, (name, s)) in panel.series.iter().enumerate() {
            let col = COLORS[i % COLORS.len()];
            let stride = (s.len() / 4000).max(1);
            c.draw_series(LineSeries::new(s.iter().step_by(stride).copied().filter(|p| p.1.is_finite()), col.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2)));
        }
        c.configure_series_labels().background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
