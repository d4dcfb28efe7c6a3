//! An estimate against its reference, with the error underneath.

use std::path::Path;

use eenf::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::*;

/// One estimate against the reference (aligned), for [`plot_methods`].
pub struct Series<'a> {
    /// Legend label.
    pub label: String,
    /// Times, s from the recording start.
    pub time_s: &'a [f64],
    /// Estimate, Hz.
    pub estimate: &'a [f64],
    /// Reference at those times, Hz.
    pub reference: &'a [f64],
    /// Colour of this series in the palette (the same method keeps its colour across figures).
    pub colour: usize,
}

fn comparison<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    series: &[Series],
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (upper, lower) = root.split_vertically(SIZE.1 as i32 * 62 / 100);
    let x = range(series.iter().flat_map(|s| s.time_s.iter().copied()));
    let y = range(
        series
            .iter()
            .flat_map(|s| s.estimate.iter().chain(s.reference).copied()),
    );
    let mut c = enf_panel(&upper, x, y)?;
    // the reference: the longest of the series' aligned references (they are the same signal)
    if let Some(r) = series.iter().max_by_key(|s| s.time_s.len()) {
        let style = BLACK.stroke_width(2);
        labelled_runs(
            &mut c,
            r.time_s,
            r.reference,
            style,
            "reference".into(),
            style,
        )?;
    }
    let colour = |s: &Series| {
        if series.len() == 1 {
            RED
        } else {
            PALETTE[s.colour % PALETTE.len()]
        }
    };
    for s in series {
        let style = colour(s).stroke_width(2);
        labelled_runs(&mut c, s.time_s, s.estimate, style, s.label.clone(), style)?;
    }
    legend(&mut c)?;
    let errors: Vec<Vec<f64>> = series
        .iter()
        .map(|s| {
            s.estimate
                .iter()
                .zip(s.reference)
                .map(|(a, b)| (a - b) * 1e3)
                .collect()
        })
        .collect();
    let ey = range(errors.iter().flatten().copied().chain([0.0]));
    let mut c = ChartBuilder::on(&lower)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, ey.0..ey.1)
        .map_err(e)?;
    c.configure_mesh()
        .x_desc("time from recording start (s)")
        .y_desc("error (mHz)")
        .y_label_formatter(&|v| tick(*v, 2))
        .x_label_formatter(&|v| whole_or_tenths(*v))
        .draw()
        .map_err(e)?;
    c.draw_series(LineSeries::new([(x.0, 0.0), (x.1, 0.0)], BLACK.mix(0.4)))
        .map_err(e)?;
    for (s, err) in series.iter().zip(&errors) {
        let col = if series.len() == 1 { BLUE } else { colour(s) };
        for run in runs(s.time_s, err) {
            c.draw_series(LineSeries::new(run, col.stroke_width(2)))
                .map_err(e)?;
        }
    }
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
    plot_methods(
        path,
        title,
        &[Series {
            label: "estimate".into(),
            time_s: t,
            estimate: est,
            reference,
            colour: 0,
        }],
    )
}

/// Several estimates (one per method) against the reference, with their errors (mHz) below.
pub fn plot_methods(path: &Path, title: &str, series: &[Series]) -> Result<()> {
    render(
        path,
        |root| comparison(root, title, series),
        |root| comparison(root, title, series),
    )
}

/// [`plot_comparison`]'s figure as SVG text.
pub fn comparison_svg(title: &str, t: &[f64], est: &[f64], reference: &[f64]) -> Result<String> {
    let series = [Series {
        label: "estimate".into(),
        time_s: t,
        estimate: est,
        reference,
        colour: 0,
    }];
    render_svg(|root| comparison(root, title, &series))
}
