//! What every figure shares: the canvas, the palette and font, rendering to PNG or SVG through
//! a temporary file, the axes' ranges and tick labels, and the ENF panel.

use std::path::Path;

use eenf::{Error, Result};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

pub(crate) const SIZE: (u32, u32) = (1100, 720);
pub(crate) const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
];

pub(crate) fn e<T: std::fmt::Display>(err: T) -> Error {
    Error::Output(format!("drawing failed: {err}"))
}

/// Registers the bundled font as plotters' `sans-serif` (once per process).
pub(crate) fn fonts() -> Result<()> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .is_ok()
    });
    if *ok {
        Ok(())
    } else {
        Err(Error::Output("the bundled font could not be loaded".into()))
    }
}

/// Renders with the backend the extension asks for, through a temporary file.
pub(crate) fn render(
    path: &Path,
    draw: impl Fn(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
    draw_svg: impl Fn(&DrawingArea<SVGBackend, Shift>) -> Result<()>,
) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    fonts()?;
    if !matches!(ext.as_str(), "png" | "svg") {
        return Err(Error::Output(format!(
            "{}: plots are written as .png or .svg",
            path.display()
        )));
    }
    let out = eenf::output::AtomicFile::keeping_extension(path)?;
    let res = match ext.as_str() {
        "png" => {
            // drawn into memory and encoded here, so that plotters needs no image crate
            let mut rgb = vec![0u8; SIZE.0 as usize * SIZE.1 as usize * 3];
            let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
            let drawn = draw(&root).and_then(|_| root.present().map_err(e));
            drop(root);
            drawn.and_then(|_| write_png(out.file()?, &rgb))
        }
        "svg" => {
            let root = SVGBackend::new(out.path(), SIZE).into_drawing_area();
            draw_svg(&root).and_then(|_| root.present().map_err(e))
        }
        _ => {
            return Err(Error::Output(format!(
                "{}: plots are written as .png or .svg",
                path.display()
            )))
        }
    };
    match res {
        Ok(()) => Ok(out.commit()?),
        Err(err) => Err(err.context(format!("{}: cannot draw the plot", path.display()))),
    }
}

/// Renders as SVG text, for a page or a report to hold inline.
pub(crate) fn render_svg(
    draw_svg: impl Fn(&DrawingArea<SVGBackend, Shift>) -> Result<()>,
) -> Result<String> {
    fonts()?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw_svg(&root).and_then(|_| root.present().map_err(e))?;
    }
    Ok(svg)
}

/// An RGB image of `SIZE` as PNG (8 bits per channel, the encoder's default compression).
pub(crate) fn write_png(file: std::fs::File, rgb: &[u8]) -> Result<()> {
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), SIZE.0, SIZE.1);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header().map_err(e)?;
    w.write_image_data(rgb).map_err(e)?;
    w.finish().map_err(e)
}

pub(crate) fn range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
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

/// The (t, v) pairs with a finite v, for line series that skip gaps.
pub(crate) fn finite_points<'a>(
    t: &'a [f64],
    v: &'a [f64],
) -> impl Iterator<Item = (f64, f64)> + 'a {
    t.iter()
        .zip(v)
        .filter(|(_, v)| v.is_finite())
        .map(|(a, b)| (*a, *b))
}

/// The runs of consecutive finite values of `v` (a gap breaks the line rather than bridging it).
pub(crate) fn runs(t: &[f64], v: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut open = false;
    for (a, b) in t.iter().zip(v) {
        if b.is_finite() {
            if !open {
                out.push(Vec::new());
                open = true;
            }
            if let Some(run) = out.last_mut() {
                run.push((*a, *b));
            }
        } else {
            open = false;
        }
    }
    out
}

/// Draws `v` over `t` as a line in `style` that gaps break (plotters has no missing value), with
/// one legend entry `label` in `legend_style`: there even when no value is drawn.
pub(crate) fn labelled_runs<DB: DrawingBackend>(
    c: &mut Panel<'_, DB>,
    t: &[f64],
    v: &[f64],
    style: ShapeStyle,
    label: String,
    legend_style: ShapeStyle,
) -> Result<()> {
    c.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
        .map_err(e)?
        .label(label)
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], legend_style));
    for run in runs(t, v) {
        c.draw_series(LineSeries::new(run, style)).map_err(e)?;
    }
    Ok(())
}

/// A tick label with `digits` decimals, never `-0.00`.
pub(crate) fn tick(v: f64, digits: usize) -> String {
    let text = format!("{v:.digits$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => text,
    }
}

/// A tick label of seconds or pixels: whole numbers without decimals.
pub(crate) fn whole_or_tenths(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        tick(v, 0)
    } else {
        tick(v, 1)
    }
}

/// A file's name for a figure's title: long names shortened in the middle, so that the title
/// fits the figure.
pub fn title_name(path: &Path) -> String {
    const MOST: usize = 44;
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let chars: Vec<char> = name.chars().collect();
    if chars.len() <= MOST {
        return name.into_owned();
    }
    let head: String = chars[..MOST / 2 - 1].iter().collect();
    let tail: String = chars[chars.len() - (MOST / 2 - 1)..].iter().collect();
    format!("{head}…{tail}")
}

pub(crate) type Panel<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The upper panel of both figures: ENF in Hz over time.
pub(crate) fn enf_panel<'a, DB: DrawingBackend>(
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
        .y_label_formatter(&|v| tick(*v, 3))
        .x_label_formatter(&|v| whole_or_tenths(*v))
        .draw()
        .map_err(e)?;
    Ok(c)
}

pub(crate) fn legend<'a, DB: DrawingBackend + 'a>(c: &mut Panel<'a, DB>) -> Result<()> {
    c.configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(e)
}

/// A perceptually ordered colour map (dark blue → yellow) for 0..=1.
pub(crate) fn heat(v: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    let v = v.clamp(0.0, 1.0);
    let k = STOPS.iter().rposition(|s| s.0 <= v).unwrap_or(0).min(3);
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let w = (v - a.0) / (b.0 - a.0);
    let c = |i: usize| (a.1[i] + (b.1[i] - a.1[i]) * w).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

/// A vertical colour bar of [`heat`] over `range` (low to high), labelled `what`.
pub(crate) fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    range: (f64, f64),
    what: &str,
) -> Result<()> {
    let mut b = ChartBuilder::on(area)
        .margin(12)
        .margin_left(4)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..1.0, range.0..range.1)
        .map_err(e)?;
    b.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .y_label_formatter(&|v| whole_or_tenths(*v))
        .y_desc(what)
        .draw()
        .map_err(e)?;
    let steps = 64;
    let at = |k: usize| range.0 + (range.1 - range.0) * k as f64 / steps as f64;
    b.draw_series((0..steps).map(|k| {
        Rectangle::new(
            [(0.0, at(k)), (1.0, at(k + 1))],
            heat(k as f64 / steps as f64).filled(),
        )
    }))
    .map_err(e)?;
    Ok(())
}
