//! A spectrogram with the traced line over it.

use std::path::Path;

use eenf::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::*;

fn spectrogram_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    s: &eenf_dsp::Spectrogram,
    line: Option<(&[f64], &[f64])>,
    floor_db: f64,
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (nt, nf) = (s.time_s.len(), s.freq_hz.len());
    if nt == 0 || nf == 0 {
        return Err(Error::Method("empty spectrogram".into()));
    }
    let dt = if nt > 1 {
        s.time_s[1] - s.time_s[0]
    } else {
        1.0
    };
    let df = if nf > 1 {
        s.freq_hz[1] - s.freq_hz[0]
    } else {
        0.01
    };
    let x = (s.time_s[0] - dt / 2.0, s.time_s[nt - 1] + dt / 2.0);
    let y = (s.freq_hz[0] - df / 2.0, s.freq_hz[nf - 1] + df / 2.0);
    let (plot_area, bar_area) = root.split_horizontally(SIZE.0 as i32 - 120);
    let mut c = ChartBuilder::on(&plot_area)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)
        .map_err(e)?;
    c.configure_mesh()
        .disable_mesh()
        .x_desc("time from recording start (s)")
        .y_desc("frequency (Hz)")
        .y_label_formatter(&|v| tick(*v, 2))
        .x_label_formatter(&|v| whole_or_tenths(*v))
        .draw()
        .map_err(e)?;
    c.draw_series((0..nt).flat_map(|i| {
        (0..nf).map(move |k| {
            let v = (s.power_db[i * nf + k] as f64 - floor_db) / -floor_db;
            Rectangle::new(
                [
                    (s.time_s[i] - dt / 2.0, s.freq_hz[k] - df / 2.0),
                    (s.time_s[i] + dt / 2.0, s.freq_hz[k] + df / 2.0),
                ],
                heat(v).filled(),
            )
        })
    }))
    .map_err(e)?;
    if let Some((t, f)) = line {
        c.draw_series(LineSeries::new(finite_points(t, f), WHITE.stroke_width(2)))
            .map_err(e)?
            .label("2 x reference ENF")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], WHITE.stroke_width(2)));
        c.configure_series_labels()
            .background_style(BLACK.mix(0.5))
            .label_font(("sans-serif", 15).into_font().color(&WHITE))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(e)?;
    }
    // colour bar
    colour_bar(&bar_area, (floor_db, 0.0), "power (dB)")?;
    Ok(())
}

/// A spectrogram (dB, clipped at `floor_db` below its peak) with an optional line drawn over
/// it (times, frequencies).
pub fn plot_spectrogram(
    path: &Path,
    title: &str,
    s: &eenf_dsp::Spectrogram,
    line: Option<(&[f64], &[f64])>,
    floor_db: f64,
) -> Result<()> {
    render(
        path,
        |root| spectrogram_chart(root, title, s, line, floor_db),
        |root| spectrogram_chart(root, title, s, line, floor_db),
    )
}
