//! Where on the sensor the flicker is: each tile's line strength.

use std::path::Path;

use eenf::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::*;

fn flicker_map_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    m: &eenf::flicker_map::FlickerMap,
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (plot_area, bar_area) = root.split_horizontally(SIZE.0 as i32 - 120);
    let (w, h) = (m.width as f64, m.height as f64);
    let mut c = ChartBuilder::on(&plot_area)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        // rows from the top, as the sensor's pixels
        .build_cartesian_2d(0.0..w, h..0.0)
        .map_err(e)?;
    c.configure_mesh()
        .disable_mesh()
        .x_desc("x (pixels)")
        .y_desc("y (pixels)")
        .x_label_formatter(&|v| whole_or_tenths(*v))
        .y_label_formatter(&|v| whole_or_tenths(*v))
        .draw()
        .map_err(e)?;
    let db = |s: f64| 20.0 * s.max(1e-9).log10();
    let top_db = m
        .strength
        .iter()
        .flatten()
        .map(|&s| db(s))
        .fold(20.0, f64::max);
    let t = m.tile as f64;
    c.draw_series((0..m.rows).flat_map(|r| {
        (0..m.cols).map(move |k| {
            let colour = match m.strength[r * m.cols + k] {
                Some(s) => heat(db(s) / top_db),
                None => RGBColor(200, 200, 200),
            };
            let (x0, y0) = (k as f64 * t, r as f64 * t);
            Rectangle::new(
                [(x0, y0), ((x0 + t).min(w), (y0 + t).min(h))],
                colour.filled(),
            )
        })
    }))
    .map_err(e)?;
    // the tiles where the line stands above the noise, outlined
    c.draw_series(m.flickering().map(|i| {
        let (r, k) = (i / m.cols, i % m.cols);
        let (x0, y0) = (k as f64 * t, r as f64 * t);
        Rectangle::new(
            [(x0, y0), ((x0 + t).min(w), (y0 + t).min(h))],
            WHITE.stroke_width(1),
        )
    }))
    .map_err(e)?
    .label(format!(
        "mains flicker: the line {:.0} dB or more over the tile's noise",
        20.0 * eenf::flicker_map::MIN_TILE_STRENGTH.log10()
    ))
    .legend(|(x, y)| {
        Rectangle::new(
            [(x, y - 6), (x + 16, y + 6)],
            RGBColor(40, 40, 40).stroke_width(2),
        )
    });
    // grey: a legend entry of its own
    c.draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())
        .map_err(e)?
        .label("too few events to tell")
        .legend(|(x, y)| {
            Rectangle::new(
                [(x, y - 6), (x + 16, y + 6)],
                RGBColor(200, 200, 200).filled(),
            )
        });
    c.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(e)?;
    colour_bar(&bar_area, (0.0, top_db), "line over noise (dB)")?;
    Ok(())
}

/// The flicker map: each tile coloured by how far its line stands above its noise (grey: too
/// few events), the tiles where it counts as mains flicker outlined in white.
pub fn plot_flicker_map(
    path: &Path,
    title: &str,
    map: &eenf::flicker_map::FlickerMap,
) -> Result<()> {
    render(
        path,
        |root| flicker_map_chart(root, title, map),
        |root| flicker_map_chart(root, title, map),
    )
}

/// [`plot_flicker_map`]'s figure as SVG text.
pub fn flicker_map_svg(title: &str, map: &eenf::flicker_map::FlickerMap) -> Result<String> {
    render_svg(|root| flicker_map_chart(root, title, map))
}

/// The flicker map's title: the recording `name`, its whole line and the share of tiles where
/// it stands out.
pub fn flicker_map_title(name: &str, map: &eenf::flicker_map::FlickerMap) -> String {
    let share = 100.0 * map.flickering_share();
    match map.whole {
        Some(l) => format!(
            "{name}: flicker at {:.3} Hz, {}; it stands out in {share:.0} % of the tiles",
            l.hz,
            l.floor_db
                .map_or(format!("prominence {:.1}", l.prominence), |db| format!(
                    "{db:.0} dB over its floor"
                ))
        ),
        None => format!("{name}: no flicker line measured"),
    }
}
