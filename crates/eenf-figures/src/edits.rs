//! The hum's phase and frequency around the edits found in it.

use std::path::Path;

use eenf::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::draw::*;

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

/// [`plot_edits`]'s figure as SVG text.
pub fn edits_svg(title: &str, report: &eenf::edits::EditReport) -> Result<String> {
    render_svg(|a| edits_chart(a, title, report))
}
