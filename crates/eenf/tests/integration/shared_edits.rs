//! `edits` against the truth: 10-minute clips of 8 kHz 16-bit sound whose hum follows the
//! phase of real mains (the six Wuhan hours of `../shared/enf-reference`, and the 60 Hz
//! traces), in white noise, cut (0.3–30 s removed) or with 2–30 s from another hour inserted,
//! or left whole. Prints the table the README quotes, and asserts what the test reaches at the
//! stated hum (0.01 at f0, 0.004 at 2f0, 0.003 at 3f0, noise std 0.05): at most one false
//! alarm in 10 hours of unedited clips; nearly every insertion, and most cuts, found within
//! 1 s of the splice. (Issue 29 asked for 90 % of single edits; cuts reach 80–88 % here, the
//! rest removing close to a whole number of mains cycles. Since issue 44 the threshold carries
//! the real grid's stray, which this smoothed phase lacks: `shared_edits_real.rs` splices the
//! real recordings themselves. The bounds below are set under what was measured so that a
//! regression fails.)
//!
//! `EENF_EDITS_SCALE` multiplies the number of clips (default 1).

use crate::common;

use std::path::Path;

use common::scale_clips;
use eenf::audio::{AudioOptions, Sound};
use eenf::edits::{sound_edits, EditParams, EditReport};
use eenf_core::Nominal;
use eenf_sim::MainsPhase;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;

const FS: f64 = 8000.0;
const CLIP_S: f64 = 600.0;
const NOISE: f64 = 0.05;
const AMPS: [f64; 3] = [0.01, 0.004, 0.003];

#[derive(Clone, Copy, Debug)]
enum Edit {
    None,
    /// `d` seconds removed at `t0`.
    Delete {
        t0: f64,
        d: f64,
    },
    /// `d` seconds of hour `from` (at `s2`) put in at `t0`.
    Insert {
        t0: f64,
        d: f64,
        from: usize,
        s2: f64,
    },
}

/// The clip's hum phase at output time `t` (s from the clip's start).
fn phase(hours: &[MainsPhase], hour: usize, start: f64, edit: Edit, t: f64) -> f64 {
    match edit {
        Edit::None => hours[hour].phase_at(start + t),
        Edit::Delete { t0, d } => hours[hour].phase_at(start + if t < t0 { t } else { t + d }),
        Edit::Insert { t0, d, from, s2 } => {
            if t < t0 {
                hours[hour].phase_at(start + t)
            } else if t < t0 + d {
                hours[from].phase_at(s2 + t - t0)
            } else {
                hours[hour].phase_at(start + t - d)
            }
        }
    }
}

/// The splices of an edit, s.
fn splices(edit: Edit) -> Vec<f64> {
    match edit {
        Edit::None => vec![],
        Edit::Delete { t0, .. } => vec![t0],
        Edit::Insert { t0, d, .. } => vec![t0, t0 + d],
    }
}

/// A clip: hum of `scale`·[`AMPS`] on the phase, white noise, 16-bit.
fn clip(
    hours: &[MainsPhase],
    hour: usize,
    start: f64,
    edit: Edit,
    scale: f64,
    seed: u64,
) -> Vec<f32> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let psi: [f64; 3] = [
        0.0,
        rng.gen_range(0.0..std::f64::consts::TAU),
        rng.gen_range(0.0..std::f64::consts::TAU),
    ];
    let n = (CLIP_S * FS) as usize;
    (0..n)
        .map(|i| {
            let phi = phase(hours, hour, start, edit, i as f64 / FS);
            let hum: f64 = AMPS
                .iter()
                .enumerate()
                .map(|(k, a)| scale * a * ((k + 1) as f64 * phi + psi[k]).cos())
                .sum();
            let g: f64 = rng.sample(StandardNormal);
            let v = ((hum + NOISE * g) * 32767.0)
                .round()
                .clamp(-32768.0, 32767.0);
            (v / 32767.0) as f32
        })
        .collect()
}

fn edits_of(samples: &[f32]) -> eenf::Result<EditReport> {
    let sound = Sound::Samples {
        name: Path::new("clip"),
        interleaved: samples,
        channels: 1,
        fs: FS,
    };
    sound_edits(
        &sound,
        &AudioOptions::default(),
        Nominal::Auto,
        &EditParams::default(),
    )
}

/// One level's outcome.
#[derive(Default, Debug)]
struct Tally {
    clips: usize,
    found: usize,
    refused: usize,
    /// Findings further than 1 s from every splice (and, for insertions, outside the
    /// inserted stretch).
    false_alarms: usize,
    hours: f64,
    /// |time − splice| of the findings that hit, s.
    errors: Vec<f64>,
}

fn run(hours: &[MainsPhase], kind: &str, clips: usize, scale: f64, seed: u64) -> Tally {
    let span = hours[0].duration_s();
    let results: Vec<(Edit, eenf::Result<EditReport>)> = (0..clips)
        .into_par_iter()
        .map(|c| {
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed * 1000 + c as u64);
            let hour = rng.gen_range(0..hours.len());
            let start = rng.gen_range(30.0..span - CLIP_S - 60.0);
            let edit = match kind {
                "none" => Edit::None,
                "delete" => {
                    let d = (rng.gen_range(0.3f64.ln()..30f64.ln())).exp();
                    Edit::Delete {
                        t0: rng.gen_range(0.2 * CLIP_S..0.8 * CLIP_S),
                        d,
                    }
                }
                _ => {
                    let d = (rng.gen_range(2f64.ln()..30f64.ln())).exp();
                    let from = (hour + rng.gen_range(1..hours.len())) % hours.len();
                    Edit::Insert {
                        t0: rng.gen_range(0.2 * CLIP_S..0.8 * CLIP_S - d),
                        d,
                        from,
                        s2: rng.gen_range(30.0..span - 60.0),
                    }
                }
            };
            let x = clip(hours, hour, start, edit, scale, seed * 7919 + c as u64);
            (edit, edits_of(&x))
        })
        .collect();
    let mut t = Tally::default();
    for (edit, r) in results {
        t.clips += 1;
        let Ok(r) = r else {
            t.refused += 1;
            continue;
        };
        t.hours += CLIP_S / 3600.0;
        let sp = splices(edit);
        let mut hit = false;
        for e in &r.edits {
            let near = sp
                .iter()
                .map(|s| (e.time_s - s).abs())
                .fold(f64::INFINITY, f64::min);
            let inside =
                matches!(edit, Edit::Insert { t0, d, .. } if e.time_s > t0 && e.time_s < t0 + d);
            if near <= 1.0 {
                hit = true;
                t.errors.push(near);
            } else if !inside {
                t.false_alarms += 1;
            }
        }
        t.found += hit as usize;
    }
    t
}

fn hours_50() -> Vec<MainsPhase> {
    common::reference_wavs()
        .iter()
        .map(|p| {
            let s = eenf::audio::read_wav(p).unwrap();
            let len = s.samples.len() as f64 / s.fs;
            MainsPhase::from_recording(&s.samples, s.fs, 50.0, 0.0, len - 1.0).unwrap()
        })
        .collect()
}

fn hours_60() -> Vec<MainsPhase> {
    let dir = common::shared("enf-traces-60hz").join("enf-traces-60hz");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .collect();
    files.sort();
    // each day cut into hours: hour h of a day is the trace from 3600·h s
    let mut out = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let freq: Vec<f64> = text
            .lines()
            .filter_map(|l| l.split(',').nth(1)?.trim().parse().ok())
            .collect();
        for h in [3usize, 9, 15, 21] {
            out.push(MainsPhase::from_frequency(
                60.0,
                &freq,
                2.0,
                3600.0 * h as f64,
                3600.0,
                0.0,
            ));
        }
    }
    out
}

/// A line of the README's table: what, hum, found, refused, false alarms, 95th percentile of
/// the time error.
fn row(name: &str, scale: f64, t: &Tally) -> String {
    let mut e = t.errors.clone();
    e.sort_by(f64::total_cmp);
    let p95 = e
        .get((e.len() as f64 * 0.95) as usize)
        .copied()
        .unwrap_or(f64::NAN);
    format!(
        "| {name} | {scale} | {}/{} ({:.1} %) | {} | {} in {:.1} h | {:.2} s |",
        t.found,
        t.clips - t.refused,
        100.0 * t.found as f64 / (t.clips - t.refused).max(1) as f64,
        t.refused,
        t.false_alarms,
        t.hours,
        p95
    )
}

#[test]
#[ignore = "needs ../shared (enf-reference, enf-traces-60hz)"]
fn edits_are_found_at_the_splice_with_few_false_alarms_on_real_mains_hum() {
    let hours = hours_50();
    let mut lines = Vec::new();
    // the acceptance: the stated hum
    let null = run(&hours, "none", scale_clips(60), 1.0, 1);
    let del = run(&hours, "delete", scale_clips(60), 1.0, 2);
    let ins = run(&hours, "insert", scale_clips(60), 1.0, 3);
    lines.push(row("unedited, 50 Hz", 1.0, &null));
    lines.push(row("cut 0.3-30 s, 50 Hz", 1.0, &del));
    lines.push(row("insert 2-30 s, 50 Hz", 1.0, &ins));
    // weaker hum: the same noise
    for (i, scale) in [0.5, 0.3, 0.2].into_iter().enumerate() {
        let s = 10 + 3 * i as u64;
        let n = run(&hours, "none", scale_clips(18), scale, s);
        let d = run(&hours, "delete", scale_clips(30), scale, s + 1);
        let k = run(&hours, "insert", scale_clips(30), scale, s + 2);
        lines.push(row("unedited, 50 Hz", scale, &n));
        lines.push(row("cut 0.3-30 s, 50 Hz", scale, &d));
        lines.push(row("insert 2-30 s, 50 Hz", scale, &k));
    }
    // 60 Hz: the traces' phase (2 s steps, smooth between them)
    let h60 = hours_60();
    let n60 = run(&h60, "none", scale_clips(18), 1.0, 40);
    let d60 = run(&h60, "delete", scale_clips(30), 1.0, 41);
    lines.push(row("unedited, 60 Hz", 1.0, &n60));
    lines.push(row("cut 0.3-30 s, 60 Hz", 1.0, &d60));
    eprintln!("| clips | hum (x the stated) | found within 1 s | refused | false alarms | 95 % of times within |");
    eprintln!("|---|---|---|---|---|---|");
    for l in &lines {
        eprintln!("{l}");
    }
    // measured: cuts 80–88 %, insertions 97–98 %, single edits together 88–93 %
    let found = del.found + ins.found;
    let clips = del.clips + ins.clips;
    assert!(
        found as f64 >= 0.85 * clips as f64,
        "{found} of {clips} single edits found"
    );
    assert!(
        ins.found as f64 >= 0.9 * ins.clips as f64,
        "insertions: {} of {}",
        ins.found,
        ins.clips
    );
    assert!(
        del.found as f64 >= 0.75 * del.clips as f64,
        "cuts: {} of {}",
        del.found,
        del.clips
    );
    assert_eq!(null.refused, 0, "unedited clips refused");
    let per_10h = null.false_alarms as f64 / null.hours * 10.0;
    assert!(
        per_10h <= 1.0,
        "{} false alarms in {:.1} h of unedited clips",
        null.false_alarms,
        null.hours
    );
    assert!(
        n60.false_alarms <= 1,
        "60 Hz: {} false alarms",
        n60.false_alarms
    );
    assert!(
        d60.found as f64 >= 0.8 * d60.clips as f64,
        "60 Hz cuts: {} of {}",
        d60.found,
        d60.clips
    );
}
