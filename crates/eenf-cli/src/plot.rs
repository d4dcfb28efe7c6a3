//! Figures: an estimate against its reference with the error underneath, and the per-harmonic
//! traces with the harmonic chosen per segment. PNG or SVG, chosen by the file's extension.

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use eenf::trace::Trace;
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

fn e<T: std::fmt::Display>(err: T) -> anyhow::Error {
    anyhow!("drawing failed: {err}")
}

/// Registers the bundled font as plotters' `sans-serif` (once per process).
fn fonts() -> Result<()> {
    static REGISTERED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .is_ok()
    });
    if *ok {
        Ok(())
    } else {
        bail!("the bundled font could not be loaded")
    }
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
    fonts()?;
    if !matches!(ext.as_str(), "png" | "svg") {
        bail!("{}: plots are written as .png or .svg", path.display());
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
        _ => bail!("{}: plots are written as .png or .svg", path.display()),
    };
    match res {
        Ok(()) => out.commit(),
        Err(err) => Err(err.context(format!("{}: cannot draw the plot", path.display()))),
    }
}

/// An RGB image of `SIZE` as PNG (8 bits per channel, the encoder's default compression).
fn write_png(file: std::fs::File, rgb: &[u8]) -> Result<()> {
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), SIZE.0, SIZE.1);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header().map_err(e)?;
    w.write_image_data(rgb).map_err(e)?;
    w.finish().map_err(e)
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

/// The (t, v) pairs with a finite v, for line series that skip gaps.
fn finite_points<'a>(t: &'a [f64], v: &'a [f64]) -> impl Iterator<Item = (f64, f64)> + 'a {
    t.iter()
        .zip(v)
        .filter(|(_, v)| v.is_finite())
        .map(|(a, b)| (*a, *b))
}

/// The runs of consecutive finite values of `v` (a gap breaks the line rather than bridging it).
fn runs(t: &[f64], v: &[f64]) -> Vec<Vec<(f64, f64)>> {
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

/// A tick label with `digits` decimals, never `-0.00`.
fn tick(v: f64, digits: usize) -> String {
    let text = format!("{v:.digits$}");
    match text.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_string(),
        _ => text,
    }
}

/// A tick label of seconds or pixels: whole numbers without decimals.
fn whole_or_tenths(v: f64) -> String {
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
        .y_label_formatter(&|v| tick(*v, 3))
        .x_label_formatter(&|v| whole_or_tenths(*v))
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
        c.draw_series(LineSeries::new(
            r.time_s.iter().zip(r.reference).map(|(a, b)| (*a, *b)),
            BLACK.stroke_width(2),
        ))
        .map_err(e)?
        .label("reference")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(2)));
    }
    let colour = |s: &Series| {
        if series.len() == 1 {
            RED
        } else {
            PALETTE[s.colour % PALETTE.len()]
        }
    };
    for s in series {
        let col = colour(s);
        c.draw_series(LineSeries::new(
            s.time_s.iter().zip(s.estimate).map(|(a, b)| (*a, *b)),
            col.stroke_width(2),
        ))
        .map_err(e)?
        .label(s.label.clone())
        .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2)));
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
        c.draw_series(LineSeries::new(
            s.time_s.iter().zip(err).map(|(a, b)| (*a, *b)),
            col.stroke_width(2),
        ))
        .map_err(e)?;
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

/// A perceptually ordered colour map (dark blue → yellow) for 0..=1.
fn heat(v: f64) -> RGBColor {
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
        bail!("empty spectrogram");
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

/// One bar group of [`plot_summary`]: a method's mean per class, and the paper's value.
pub struct SummaryBar {
    /// Class.
    pub class: String,
    /// Method label.
    pub method: String,
    /// Index of the method (colour).
    pub method_index: usize,
    /// eenf's mean CC (NaN when nothing was scored).
    pub cc: f64,
    /// eenf's mean MAE, mHz.
    pub mae_mhz: f64,
    /// The paper's (CC, MAE mHz).
    pub paper: Option<(f64, f64)>,
}

/// What one panel of the summary shows.
struct BarPanel<'a> {
    caption: &'a str,
    y_desc: &'a str,
    /// eenf's value of a bar.
    value: fn(&SummaryBar) -> f64,
    /// The paper's value from its (CC, MAE).
    paper: fn((f64, f64)) -> f64,
    /// Where the bars start (0, or the bottom of a log axis).
    base: f64,
    /// Where the legend goes (one panel carries it).
    legend: Option<SeriesLabelPosition>,
}

fn bar_panel<DB: DrawingBackend, Y>(
    area: &DrawingArea<DB, Shift>,
    y: Y,
    p: &BarPanel,
    classes: &[String],
    methods: &[String],
    bars: &[SummaryBar],
) -> Result<()>
where
    Y: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
    Y::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
{
    let nm = methods.len().max(1) as f64;
    let slot = |b: &SummaryBar| {
        let ci = classes.iter().position(|c| *c == b.class).unwrap_or(0) as f64;
        let x0 = ci + 0.1 + 0.8 * b.method_index as f64 / nm;
        (x0, x0 + 0.8 / nm)
    };
    let mut c = ChartBuilder::on(area)
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .caption(p.caption, ("sans-serif", 18))
        .build_cartesian_2d(0.0..classes.len() as f64, y)
        .map_err(e)?;
    let names = classes.to_vec();
    c.configure_mesh()
        .disable_x_mesh()
        .x_labels(classes.len() * 2 + 1)
        .x_label_formatter(&|v| {
            let k = v.floor() as usize;
            if (v - k as f64 - 0.5).abs() < 1e-6 {
                names.get(k).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        })
        .x_desc("scene class")
        .y_desc(p.y_desc)
        .y_label_formatter(&|v| {
            if *v >= 1.0 {
                whole_or_tenths(*v)
            } else {
                // CC and small MAE: as few decimals as the value needs
                let t = tick(*v, 3);
                t.trim_end_matches('0').trim_end_matches('.').to_string()
            }
        })
        .draw()
        .map_err(e)?;
    for (k, m) in methods.iter().enumerate() {
        let col = PALETTE[k % PALETTE.len()];
        c.draw_series(bars.iter().filter(|b| b.method_index == k).filter_map(|b| {
            let v = (p.value)(b);
            v.is_finite().then(|| {
                let (x0, x1) = slot(b);
                Rectangle::new([(x0, p.base), (x1, v.max(p.base))], col.filled())
            })
        }))
        .map_err(e)?
        .label(format!("{m} (eenf)"))
        .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], col.filled()));
    }
    // a method that scored nothing in a class says so where its bar would be
    let text_y = if p.base > 0.0 { p.base * 1.3 } else { 0.02 };
    c.draw_series(
        bars.iter()
            .filter(|b| !(p.value)(b).is_finite())
            .map(|b| Text::new("failed", (slot(b).0, text_y), ("sans-serif", 13))),
    )
    .map_err(e)?;
    // the paper's values: black ticks across each bar
    c.draw_series(bars.iter().filter_map(|b| {
        b.paper.map(|pv| {
            let v = (p.paper)(pv);
            let (x0, x1) = slot(b);
            PathElement::new([(x0, v), (x1, v)], BLACK.stroke_width(3))
        })
    }))
    .map_err(e)?
    .label("paper (real EV-ENFD)")
    .legend(|(x, y)| PathElement::new([(x, y), (x + 14, y)], BLACK.stroke_width(3)));
    if let Some(pos) = &p.legend {
        c.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(pos.clone())
            .draw()
            .map_err(e)?;
    }
    Ok(())
}

fn summary_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    classes: &[String],
    methods: &[String],
    bars: &[SummaryBar],
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(e)?;
    let (left, right) = root.split_horizontally(SIZE.0 as i32 / 2);
    let cc_low = bars
        .iter()
        .flat_map(|b| [b.cc, b.paper.map_or(0.0, |p| p.0)])
        .filter(|v| v.is_finite())
        .fold(0.0, f64::min);
    bar_panel(
        &left,
        cc_low..1.0,
        &BarPanel {
            caption: "mean CC (higher is better)",
            y_desc: "CC",
            value: |b| b.cc,
            paper: |p| p.0,
            base: 0.0,
            legend: None,
        },
        classes,
        methods,
        bars,
    )?;
    // MAE spans decades (a failing method's hundreds of mHz beside a fraction of one): log axis
    let maes = || {
        bars.iter()
            .flat_map(|b| [b.mae_mhz, b.paper.map_or(f64::NAN, |p| p.1)])
            .filter(|v| v.is_finite() && *v > 0.0)
    };
    let lo = 10f64.powf(
        maes()
            .fold(f64::INFINITY, f64::min)
            .min(1.0)
            .log10()
            .floor(),
    );
    let hi = 10f64.powf(maes().fold(0.0, f64::max).max(10.0).log10().ceil());
    bar_panel(
        &right,
        (lo..hi).log_scale(),
        &BarPanel {
            caption: "mean MAE, mHz, log scale (lower is better)",
            y_desc: "MAE (mHz)",
            value: |b| b.mae_mhz,
            paper: |p| p.1,
            base: lo,
            legend: Some(SeriesLabelPosition::UpperRight),
        },
        classes,
        methods,
        bars,
    )
}

/// Mean CC and MAE per class and method as grouped bars, with the paper's values as ticks.
pub fn plot_summary(
    path: &Path,
    title: &str,
    classes: &[String],
    methods: &[String],
    bars: &[SummaryBar],
) -> Result<()> {
    render(
        path,
        |root| summary_chart(root, title, classes, methods, bars),
        |root| summary_chart(root, title, classes, methods, bars),
    )
}

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
        let mut first = true;
        for run in runs(t, &shown) {
            let drawn = c
                .draw_series(LineSeries::new(run, col.mix(0.45).stroke_width(1)))
                .map_err(e)?;
            if std::mem::take(&mut first) {
                drawn.label(label.clone()).legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], col.mix(0.45).stroke_width(2))
                });
            }
        }
        if first {
            // every estimate of the band off the scale (or none): named all the same
            c.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(e)?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], col.mix(0.45).stroke_width(2))
                });
        }
    }
    let mut first = true;
    for run in runs(t, &tr.enf_hz) {
        let drawn = c
            .draw_series(LineSeries::new(run, BLACK.stroke_width(3)))
            .map_err(e)?;
        if std::mem::take(&mut first) {
            drawn
                .label("ENF (the selected band's)")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(3)));
        }
    }
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

/// A vertical colour bar of [`heat`] over `range` (low to high), labelled `what`.
fn colour_bar<DB: DrawingBackend>(
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

/// At most this many points per series in the edits figure (an hour has 36 000 blocks).
const EDIT_POINTS: usize = 4000;

/// `(t, v)` thinned to at most [`EDIT_POINTS`]: the largest |v| of each chunk, so that a
/// spike survives.
fn thinned(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    let chunk = t.len().div_ceil(EDIT_POINTS).max(1);
    t.chunks(chunk)
        .zip(v.chunks(chunk))
        .filter_map(|(tc, vc)| {
            tc.iter()
                .zip(vc)
                .filter(|(_, v)| v.is_finite())
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .map(|(a, b)| (*a, *b))
        })
        .collect()
}

fn edits_chart<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    r: &eenf::edits::EditReport,
) -> Result<()> {
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(title, ("sans-serif", 20)).map_err(e)?;
    let s = &r.series;
    let x = (
        s.time_s.first().copied().unwrap_or(0.0),
        s.time_s.last().copied().unwrap_or(1.0).max(1e-3),
    );
    let has_phase = !s.phase_deg.is_empty();
    let areas = root.split_evenly((if has_phase { 3 } else { 1 }, 1));
    let marks: Vec<(f64, bool, f64)> = r
        .edits
        .iter()
        .map(|ed| {
            (
                ed.time_s,
                ed.kind == eenf::edits::EditKind::HumGap,
                ed.strength,
            )
        })
        .collect();
    // a strong edit stands hundreds of times over the threshold: the test's scale stops at a
    // few times it, so that the threshold and the weaker peaks stay in view
    const CAP: f64 = 4.0;
    let mut i = 0;
    let last = areas.len() - 1;
    let mut panel = |area: &DrawingArea<DB, Shift>,
                     y_desc: &str,
                     pts: Vec<(f64, f64)>,
                     colour: RGBColor,
                     label: &str,
                     threshold: Option<f64>,
                     peaks: bool|
     -> Result<()> {
        let (lo, hi) = range(pts.iter().map(|p| p.1).chain(threshold));
        let mut c = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(if i == last { 40 } else { 20 })
            .y_label_area_size(80)
            .build_cartesian_2d(x.0..x.1, lo..hi)
            .map_err(e)?;
        let span = hi - lo;
        let digits = if span >= 20.0 {
            0
        } else if span >= 2.0 {
            1
        } else if span >= 0.2 {
            2
        } else {
            3
        };
        let fmt = move |v: &f64| tick(*v, digits);
        let mut mesh = c.configure_mesh();
        mesh.x_label_formatter(&|v| whole_or_tenths(*v))
            .y_desc(y_desc)
            .y_label_formatter(&fmt);
        if i == last {
            mesh.x_desc("time from recording start (s)");
        }
        mesh.draw().map_err(e)?;
        for st in &r.undecided {
            c.draw_series([Rectangle::new(
                [(st.start_s, lo), (st.end_s, hi)],
                RGBColor(200, 200, 200).mix(0.5).filled(),
            )])
            .map_err(e)?;
        }
        c.draw_series(LineSeries::new(pts, colour.stroke_width(1)))
            .map_err(e)?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
        if let Some(th) = threshold {
            c.draw_series(LineSeries::new(
                [(x.0, th), (x.1, th)],
                BLACK.stroke_width(1),
            ))
            .map_err(e)?
            .label("threshold")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(1)));
        }
        // each finding: a faint line (the curve stays visible through it), its number at the
        // top, and on the test's panel a ring on its own peak
        for (k, &(t, gap, strength)) in marks.iter().enumerate() {
            let col = if gap { PALETTE[3] } else { RED };
            let series = c
                .draw_series(LineSeries::new(
                    [(t, lo), (t, hi)],
                    col.mix(0.35).stroke_width(1),
                ))
                .map_err(e)?;
            if k == 0 {
                series.label("finding (numbered)").legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], col.stroke_width(2))
                });
            }
            c.draw_series([Text::new(
                format!("{}", k + 1),
                (t, hi),
                ("sans-serif", 14).into_font().color(&col),
            )])
            .map_err(e)?;
            if peaks && !gap {
                c.draw_series([Circle::new((t, strength.min(CAP)), 5, col.stroke_width(2))])
                    .map_err(e)?;
            }
        }
        if !r.undecided.is_empty() {
            c.draw_series([Rectangle::new(
                [(x.0, lo), (x.0, lo)],
                RGBColor(200, 200, 200).filled(),
            )])
            .map_err(e)?
            .label("too weak to tell")
            .legend(|(x, y)| {
                Rectangle::new(
                    [(x, y - 5), (x + 20, y + 5)],
                    RGBColor(200, 200, 200).filled(),
                )
            });
        }
        legend(&mut c)?;
        i += 1;
        Ok(())
    };
    let mut k = 0;
    if has_phase {
        panel(
            &areas[k],
            &format!(
                "phase deviation (° at {:.0} Hz)",
                r.lines_hz.first().copied().unwrap_or(r.grid_hz)
            ),
            thinned(&s.time_s, &s.phase_deg),
            PALETTE[0],
            "lowest line's phase minus its 20 s mean (a splice turns every line)",
            None,
            false,
        )?;
        k += 1;
        let strength = thinned(&s.time_s, &s.strength);
        let clipped = strength.iter().any(|p| p.1 > CAP);
        let side = r
            .tested_side_s
            .map_or(String::new(), |s| format!(", {s:.0} s sides"));
        let label = if clipped {
            format!("phase-jump test as decided{side} (cut off at {CAP:.0}×)")
        } else {
            format!("phase-jump test as decided{side}")
        };
        panel(
            &areas[k],
            "test statistic / threshold",
            strength.into_iter().map(|(t, v)| (t, v.min(CAP))).collect(),
            PALETTE[1],
            &label,
            Some(1.0),
            true,
        )?;
        k += 1;
    }
    panel(
        &areas[k],
        "ENF (Hz)",
        thinned(
            &s.time_s,
            &s.enf_hz.iter().map(|v| v - r.grid_hz).collect::<Vec<_>>(),
        )
        .into_iter()
        .map(|(t, v)| (t, v + r.grid_hz))
        .collect(),
        PALETTE[2],
        "ENF",
        None,
        false,
    )?;
    Ok(())
}

/// The edits figure: the hum's phase deviation, the phase-jump test against its threshold
/// and the ENF over time, with the edits marked and the stretches too weak to tell shaded.
pub fn plot_edits(path: &Path, title: &str, report: &eenf::edits::EditReport) -> Result<()> {
    render(
        path,
        |a| edits_chart(a, title, report),
        |a| edits_chart(a, title, report),
    )
}
