//! A trace's harmonics, with the one chosen in each segment.

use std::path::Path;

use eenf::trace::Trace;
use eenf::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::*;

fn extraction<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    tr: &Trace,
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (upper, lower) = root.split_vertically(SIZE.1 as i32 * 68 / 100);
    let n = tr.enf_hz.len();
    let t = &tr.time_s;
    let x = (0.0, (n.max(2) - 1) as f64 * tr.step_s);
    // the scale is the selected trace's (at least ±10 mHz): bands that locked on noise run off
    // it rather than flattening the ENF into a line
    let y = {
        let (lo, hi) = if tr.finite().next().is_some() {
            range(tr.enf_hz.iter().copied())
        } else {
            range(tr.harmonics.iter().flat_map(|h| h.enf_hz.iter().copied()))
        };
        let mid = (lo + hi) / 2.0;
        let half = ((hi - lo) / 2.0).max(0.01);
        (mid - half, mid + half)
    };
    let mut c = enf_panel(&upper, x, y)?;
    let inside = |v: f64| v >= y.0 && v <= y.1;
    // what a band's estimate is divided by: 2m for flicker bands (2m·f0), k for hum (k·f0)
    let f0 = tr.nominal_hz.unwrap_or((y.0 + y.1) / 2.0);
    let divisor = |h: &eenf::trace::HarmonicPart| (h.center_hz / f0).round().max(1.0) as usize;
    let flicker = tr.harmonics.iter().all(|h| divisor(h) == 2 * h.harmonic);
    for (k, h) in tr.harmonics.iter().enumerate() {
        let col = PALETTE[k % PALETTE.len()];
        let shown: Vec<f64> = h
            .enf_hz
            .iter()
            .map(|&v| if inside(v) { v } else { f64::NAN })
            .collect();
        let off = h
            .enf_hz
            .iter()
            .filter(|v| v.is_finite() && !inside(**v))
            .count();
        let label = match off {
            0 => format!("{:.0} Hz band (÷{})", h.center_hz, divisor(h)),
            _ => format!(
                "{:.0} Hz band (÷{}), {off} off the scale",
                h.center_hz,
                divisor(h)
            ),
        };
        // a band with every estimate off the scale (or none) is named all the same
        let (line, key) = (col.mix(0.45).stroke_width(1), col.mix(0.45).stroke_width(2));
        labelled_runs(&mut c, t, &shown, line, label, key)?;
    }
    let style = BLACK.stroke_width(3);
    labelled_runs(
        &mut c,
        t,
        &tr.enf_hz,
        style,
        "ENF (the selected band's)".into(),
        style,
    )?;
    let noise: Vec<(f64, f64)> = tr
        .at_noise_level()
        .into_iter()
        .filter_map(|i| Some((*t.get(i)?, tr.enf_hz[i])))
        .collect();
    if !noise.is_empty() {
        c.draw_series(
            noise
                .iter()
                .map(|&p| Circle::new(p, 5, RED.stroke_width(2))),
        )
        .map_err(e)?
        .label(format!(
            "at the noise level (line under {} dB)",
            eenf_dsp::NOISE_LEVEL_DB
        ))
        .legend(|(x, y)| Circle::new((x + 10, y), 5, RED.stroke_width(2)));
    }
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
        .y_desc(if flicker {
            "band taken (m: 2m·f0)"
        } else {
            "band taken (k: k·f0)"
        })
        .y_labels(mmax as usize)
        .y_label_formatter(&|v| tick(*v, 0))
        .x_label_formatter(&|v| whole_or_tenths(*v))
        .draw()
        .map_err(e)?;
    let seg = tr.segment_s().unwrap_or(x.1);
    c.draw_series(tr.selected.iter().map(|s| {
        let m = s.harmonic;
        let col = tr
            .harmonics
            .iter()
            .position(|h| h.harmonic == m)
            .map(|k| PALETTE[k % PALETTE.len()])
            .unwrap_or(BLACK);
        Rectangle::new(
            [
                (s.start_s, m as f64 - 0.35),
                ((s.start_s + seg).min(x.1), m as f64 + 0.35),
            ],
            col.filled(),
        )
    }))
    .map_err(e)?;
    Ok(())
}

/// Per-harmonic traces, the selected trace, and the harmonic chosen per segment.
pub fn plot_extraction(path: &Path, title: &str, trace: &Trace) -> Result<()> {
    render(
        path,
        |root| extraction(root, title, trace),
        |root| extraction(root, title, trace),
    )
}

/// [`plot_extraction`]'s figure as SVG text.
pub fn extraction_svg(title: &str, trace: &Trace) -> Result<String> {
    render_svg(|root| extraction(root, title, trace))
}
