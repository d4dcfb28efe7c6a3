//! A benchmark's summary: one bar per method and recording class.

use std::path::Path;

use eenf::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::*;

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
