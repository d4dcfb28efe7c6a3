//! Figures: an estimate against its reference with the error underneath, and the per-harmonic
//! traces with the harmonic chosen per segment. PNG or SVG, chosen by the file's extension.

use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use eenf_dsp::EnfTrace;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

const SIZE: (u32, u32) = (1100, 720);
const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
];

fn e<T: std::fmt::Debug>(err: T) -> anyhow::Error {
    anyhow!("drawing failed: {err:?}")
}

/// Renders with the backend the extension asks for, through a temporary file.
fn render(
    path: &Path,
    draw: impl Fn(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
    draw_svg: impl Fn(&DrawingArea<SVGBackend, Shift>) -> Result<()>,
) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("plot");
    // the backend picks the image format from the extension, so the temporary name keeps it
    let tmp_name = format!(".{stem}.{}.tmp.{ext}", std::process::id());
    let tmp = if eenf_events::is_special_file(path) {
        std::env::temp_dir().join(tmp_name)
    } else {
        path.with_file_name(tmp_name)
    };
    let res = match ext.as_str() {
        "png" => {
            let root = BitMapBackend::new(&tmp, SIZE).into_drawing_area();
            draw(&root).and_then(|_| root.present().map_err(e))
        }
        "svg" => {
            let root = SVGBackend::new(&tmp, SIZE).into_drawing_area();
            draw_svg(&root).and_then(|_| root.present().map_err(e))
        }
        _ => bail!("{}: plots are written as .png or .svg", path.display()),
    };
    match res {
        Ok(()) => {
            eenf_events::commit_tmp(&tmp, path).with_context(|| format!("{}", path.display()))
        }
        Err(err) => {
            let _ = std::fs::remove_file(&tmp);
            Err(err.context(format!("{}: cannot draw the plot", path.display())))
        }
    }
}

fn range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = vals
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.08).max(1e-4);
    (lo - pad, hi + pad)
}

type Panel<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The upper panel of both figures: ENF in Hz over time.
fn enf_panel<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    x: (f64, f64),
    y: (f64, f64),
) -> Result<Panel<'a, DB>> {
    let mut c = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(30)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(e)?;
    c.configure_mesh()
        .y_desc("ENF (Hz)")
        .y_label_formatter(&|v| format!("{v:.3}"))
        .draw()
        .map_err(e)?;
    Ok(c)
}

fn legend<'a, DB: DrawingBackend + 'a>(c: &mut Panel<'a, DB>) -> Result<()> {
    c.configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)
}

fn comparison<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    t: &[f64],
    est: &[f64],
    reference: &[f64],
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (upper, lower) = root.split_vertically(SIZE.1 as i32 * 62 / 100);
    let x = range(t.iter().copied());
    let y = range(est.iter().chain(reference).copied());
    let mut c = enf_panel(&upper, x, y)?;
    c.draw_series(LineSeries::new(
        t.iter().zip(reference).map(|(a, b)| (*a, *b)),
        BLACK.stroke_width(2),
    ))
    .map_err(e)?
    .label("reference")
    .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    c.draw_series(LineSeries::new(
        t.iter().zip(est).map(|(a, b)| (*a, *b)),
        RED.stroke_width(2),
    ))
    .map_err(e)?
    .label("estimate")
    .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2)));
    legend(&mut c)?;
    let err: Vec<f64> = est
        .iter()
        .zip(reference)
        .map(|(a, b)| (a - b) * 1e3)
        .collect();
    let ey = range(err.iter().copied().chain([0.0]));
    let mut c = ChartBuilder::on(&lower)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, ey.0..ey.1)
        .map_err(e)?;
    c.configure_mesh()
        .x_desc("time from recording start (s)")
        .y_desc("error (mHz)")
        .y_label_formatter(&|v| format!("{v:.2}"))
        .draw()
        .map_err(e)?;
    c.draw_series(LineSeries::new([(x.0, 0.0), (x.1, 0.0)], BLACK.mix(0.4)))
        .map_err(e)?;
    c.draw_series(LineSeries::new(
        t.iter().zip(&err).map(|(a, b)| (*a, *b)),
        BLUE.stroke_width(2),
    ))
    .map_err(e)?;
    Ok(())
}

/// Estimate and reference over time, with the error (mHz) below.
pub fn plot_comparison(
    path: &Path,
    title: &str,
    t: &[f64],
    est: &[f64],
    reference: &[f64],
) -> Result<()> {
    render(
        path,
        |root| comparison(root, title, t, est, reference),
        |root| comparison(root, title, t, est, reference),
    )
}

fn extraction<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    tr: &EnfTrace,
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (upper, lower) = root.split_vertically(SIZE.1 as i32 * 68 / 100);
    let n = tr.enf_hz.len();
    let t: Vec<f64> = (0..n).map(|i| i as f64 * tr.step_s).collect();
    let x = (0.0, (n.max(2) - 1) as f64 * tr.step_s);
    let y = range(tr.harmonics.iter().flat_map(|h| h.enf_hz.iter().copied()));
    let mut c = enf_panel(&upper, x, y)?;
    for (k, h) in tr.harmonics.iter().enumerate() {
        let col = PALETTE[k % PALETTE.len()];
        c.draw_series(LineSeries::new(
            t.iter()
                .zip(&h.enf_hz)
                .filter(|(_, v)| v.is_finite())
                .map(|(a, b)| (*a, *b)),
            col.stroke_width(1),
        ))
        .map_err(e)?
        .label(format!("{} Hz band / {}", h.center_hz, 2 * h.harmonic))
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2)));
    }
    c.draw_series(LineSeries::new(
        t.iter()
            .zip(&tr.enf_hz)
            .filter(|(_, v)| v.is_finite())
            .map(|(a, b)| (*a, *b)),
        BLACK.stroke_width(3),
    ))
    .map_err(e)?
    .label("selected (ENF)")
    .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(3)));
    legend(&mut c)?;
    let mmax = tr.harmonics.iter().map(|h| h.harmonic).max().unwrap_or(1) as f64;
    let mut c = ChartBuilder::on(&lower)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, 0.5..mmax + 0.5)
        .map_err(e)?;
    c.configure_mesh()
        .x_desc("time from recording start (s)")
        .y_desc("harmonic m (2m·f0)")
        .y_labels(mmax as usize)
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .map_err(e)?;
    let seg = tr.segment_len as f64 * tr.step_s;
    c.draw_series(tr.selected.iter().enumerate().map(|(i, &m)| {
        let col = tr
            .harmonics
            .iter()
            .position(|h| h.harmonic == m)
            .map(|k| PALETTE[k % PALETTE.len()])
            .unwrap_or(BLACK);
        Rectangle::new(
            [
                (i as f64 * seg, m as f64 - 0.35),
                (((i + 1) as f64 * seg).min(x.1), m as f64 + 0.35),
            ],
            col.filled(),
        )
    }))
    .map_err(e)?;
    Ok(())
}

/// Per-harmonic traces, the selected trace, and the harmonic chosen per segment.
pub fn plot_extraction(path: &Path, title: &str, trace: &EnfTrace) -> Result<()> {
    render(
        path,
        |root| extraction(root, title, trace),
        |root| extraction(root, title, trace),
    )
}
