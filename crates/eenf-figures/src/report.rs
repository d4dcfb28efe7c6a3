//! What an analysis says, for people: the one-line verdicts, the figures as SVG, and the
//! report an examiner attaches to a case file (one HTML file, figures inline, nothing fetched).

use eenf::analysis::{Analysis, AnalysisSettings};
use eenf::Result;
use serde_json::Value;

use crate::{comparison_svg, edits_svg, extraction_svg, flicker_map_svg, flicker_map_title};

/// The figures of an analysis, as SVG text (`None` where there is nothing to draw).
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Figures {
    /// The trace: each harmonic's and the one chosen (as `extract --plot`).
    pub trace: Option<String>,
    /// The trace against the best candidate of the first store that gave one (as `match
    /// --plot`).
    pub matched: Option<String>,
    /// The hum's phase with the edits found (as `edits --plot`).
    pub edits: Option<String>,
    /// Where in the view the flicker is (event files; as `flicker-map`).
    pub flicker_map: Option<String>,
}

/// Draws the figures of `a`, whose file is called `name`.
pub fn figures(a: &Analysis, name: &str) -> Result<Figures> {
    let trace = Some(extraction_svg(name, &a.trace)?);
    let edits = match &a.edits {
        Ok(r) if !r.series.time_s.is_empty() => Some(edits_svg(name, r)?),
        _ => None,
    };
    let flicker_map = match &a.flicker_map {
        Some(Ok(m)) => Some(flicker_map_svg(&flicker_map_title(name, m), m)?),
        _ => None,
    };
    let mut matched = None;
    if let Some((l, p)) = a.matches.iter().find_map(|m| {
        let l = m.result.as_ref().ok()?;
        Some((l, l.report.placements.first()?))
    }) {
        let r = &l.references[p.series];
        let c = &p.candidate;
        let k = c.offset.round().max(0.0) as usize;
        let q = eenf_dsp::resample::resample(&a.trace.enf_hz, a.trace.step_s, r.step);
        let n = q.len().min(r.values.len().saturating_sub(k));
        let t: Vec<f64> = (0..n).map(|i| i as f64 * r.step).collect();
        let title = format!(
            "{name} at {}: CC {:.4}, p {:.1e}",
            r.time_label(c.offset),
            c.agreement.cc,
            c.p_value
        );
        matched = Some(comparison_svg(
            &title,
            &t,
            &q[..n],
            &r.values.window(k, n)?,
        )?);
    }
    Ok(Figures {
        trace,
        matched,
        edits,
        flicker_map,
    })
}

/// The trace's verdict: `50 Hz grid, 300 estimates (1 s apart)`, or why there is no grid.
pub fn trace_verdict(a: &Analysis) -> String {
    let grid = a.trace.grid().map_or("grid not known".to_string(), |g| {
        format!("{} Hz grid", g.hz())
    });
    format!(
        "{grid}, {} estimates ({} s apart)",
        a.estimates(),
        a.trace.step_s
    )
}

/// The search's verdict per store: where it fits, at what chance of a fit that good by luck.
pub fn match_verdicts(a: &Analysis) -> Vec<String> {
    a.matches
        .iter()
        .map(|m| {
            let store = m.store.display();
            match &m.result {
                Err(e) => {
                    // the library's message names the store already, where it is about it
                    let why = e.report();
                    if why.starts_with(&store.to_string()) {
                        why
                    } else {
                        format!("{store}: {why}")
                    }
                }
                Ok(l) => match l.report.placements.first() {
                    None => format!("{store}: no place fits"),
                    Some(p) => {
                        let r = &l.references[p.series];
                        let c = &p.candidate;
                        let when = r.time_label(c.offset);
                        if c.p_value < a.query.alpha {
                            format!(
                                "recorded at {when} on {}: CC {:.4}, p {:.1e} (a match below α = {})",
                                r.name, c.agreement.cc, c.p_value, a.query.alpha
                            )
                        } else {
                            format!(
                                "no match in {store}: the best, {when} on {}, has p {:.2} (α = {})",
                                r.name, c.p_value, a.query.alpha
                            )
                        }
                    }
                },
            }
        })
        .collect()
}

/// The edits test's verdict, with its stated false-alarm rate.
pub fn edits_verdict(a: &Analysis) -> String {
    match &a.edits {
        Ok(r) => format!(
            "{} (false alarms held to {} per hour of unedited recording)",
            r.verdict, r.params.false_alarms_per_hour
        ),
        Err(e) => format!("not tested: {}", e.report()),
    }
}

/// What the report holds beside the analysis.
#[derive(Debug, Clone)]
pub struct ReportFacts<'a> {
    /// The input's name as its owner gave it.
    pub name: &'a str,
    /// Its size, bytes.
    pub size: u64,
    /// Its SHA-256, hex.
    pub sha256: &'a str,
    /// When the analysis ran, UTC (ISO 8601).
    pub analysed_at: &'a str,
    /// The options given, as JSON (the rest at their defaults, listed in full).
    pub options: &'a str,
    /// Every option of every step.
    pub settings: &'a AnalysisSettings,
}

/// `s` safe inside HTML text and attribute values.
pub fn escape_html(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

/// JSON safe inside a `<script type="application/json">` element.
fn script_json(v: &Value) -> String {
    v.to_string()
        .replace('<', "\\u003c")
        .replace('>', "\\u003e")
        .replace('&', "\\u0026")
}

/// The report: one self-contained HTML file (no script runs, nothing is fetched) with the
/// input's name, size and SHA-256, eenf's version, every parameter, the verdicts with their
/// stated error rates, the figures inline and the trace's values (a table, and the trace's
/// JSON in `<script id="trace-json" type="application/json">` for programs).
pub fn html_report(a: &Analysis, f: &Figures, facts: &ReportFacts) -> String {
    let e = escape_html;
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
    h.push_str(&format!("<title>eenf report: {}</title>", e(facts.name)));
    h.push_str(
        "<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em}\
         table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 6px;text-align:left}\
         svg{max-width:100%;height:auto}pre{white-space:pre-wrap}</style></head><body>\n",
    );
    h.push_str(&format!("<h1>eenf report: {}</h1>\n", e(facts.name)));
    h.push_str("<table id=\"facts\">\n");
    let rows = [
        ("file", facts.name.to_string()),
        ("size", format!("{} bytes", facts.size)),
        ("SHA-256", facts.sha256.to_string()),
        ("read as", a.kind.name().to_string()),
        ("analysed", facts.analysed_at.to_string()),
        ("took", format!("{:.1} s", a.seconds)),
        ("eenf", env!("CARGO_PKG_VERSION").to_string()),
    ];
    for (k, v) in rows {
        h.push_str(&format!("<tr><th>{k}</th><td>{}</td></tr>\n", e(&v)));
    }
    h.push_str("</table>\n<h2>ENF trace</h2>\n");
    h.push_str(&format!("<p id=\"verdict\">{}</p>\n", e(&trace_verdict(a))));
    if let Some(line) = a.trace.line_text() {
        h.push_str(&format!("<p>{}</p>\n", e(&line)));
    }
    for w in a.trace.notices() {
        h.push_str(&format!("<p class=\"warning\">{}</p>\n", e(&w)));
    }
    if let Some(svg) = &f.trace {
        h.push_str(&format!("<div id=\"trace\">{svg}</div>\n"));
    }
    if let Some(svg) = &f.flicker_map {
        h.push_str(&format!(
            "<h3>Where the flicker is</h3>\n<div>{svg}</div>\n"
        ));
    }
    h.push_str("<h2>When it was recorded</h2>\n");
    if a.matches.is_empty() {
        h.push_str("<p>No reference store was searched.</p>\n");
    }
    for v in match_verdicts(a) {
        h.push_str(&format!("<p class=\"match\">{}</p>\n", e(&v)));
    }
    h.push_str(
        "<p>p: the chance that a recording from no time in the store fits this well somewhere \
         (the search's null model, fitted to the scores of the whole span).</p>\n",
    );
    for m in &a.matches {
        if let Ok(l) = &m.result {
            let j = l.to_json(std::path::Path::new(facts.name), a.query.alpha);
            h.push_str("<table class=\"candidates\"><tr><th>rank</th><th>start (UTC)</th><th>grid</th><th>CC</th><th>MAE mHz</th><th>p</th></tr>\n");
            for (i, c) in j["candidates"].as_array().into_iter().flatten().enumerate() {
                h.push_str(&format!(
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.4}</td><td>{:.3}</td><td>{:.1e}</td></tr>\n",
                    i + 1,
                    e(c["start_utc"].as_str().or(c["start"].as_str()).unwrap_or("")),
                    e(c["reference"].as_str().unwrap_or("")),
                    c["cc"].as_f64().unwrap_or(f64::NAN),
                    c["mae_hz"].as_f64().unwrap_or(f64::NAN) * 1e3,
                    c["p_value"].as_f64().unwrap_or(f64::NAN),
                ));
            }
            h.push_str("</table>\n");
        }
    }
    if let Some(svg) = &f.matched {
        h.push_str(&format!("<div>{svg}</div>\n"));
    }
    h.push_str("<h2>Edits</h2>\n");
    h.push_str(&format!("<p id=\"edits\">{}</p>\n", e(&edits_verdict(a))));
    if let Ok(r) = &a.edits {
        for x in &r.edits {
            h.push_str(&format!(
                "<p>{:.1} s: {} (p {:.1e}). {}</p>\n",
                x.time_s,
                x.kind,
                x.p_value,
                e(&x.reading)
            ));
        }
    }
    if let Some(svg) = &f.edits {
        h.push_str(&format!("<div>{svg}</div>\n"));
    }
    h.push_str("<h2>Parameters</h2>\n");
    h.push_str(&format!(
        "<p>Given: <code>{}</code>; every other option at eenf's default. All of them:</p>\n<pre>{}</pre>\n",
        e(facts.options),
        e(&facts.settings.describe())
    ));
    h.push_str("<h2>What the file is</h2>\n");
    h.push_str(&format!(
        "<pre>{}</pre>\n",
        e(&serde_json::to_string_pretty(&a.about).unwrap_or_default())
    ));
    h.push_str("<h2>Trace values</h2>\n<details><summary>time_s, enf_hz</summary><table id=\"values\"><tr><th>time_s</th><th>enf_hz</th></tr>\n");
    for (t, v) in a.trace.time_s.iter().zip(&a.trace.enf_hz) {
        h.push_str(&format!("<tr><td>{t}</td><td>{v}</td></tr>\n"));
    }
    h.push_str("</table></details>\n");
    h.push_str(&format!(
        "<script id=\"trace-json\" type=\"application/json\">{}</script>\n",
        script_json(&a.trace.to_json_value())
    ));
    h.push_str("</body></html>\n");
    h
}
