//! Every figure drawn from known data: written whole as PNG (the canvas' size) and as SVG (with
//! its title), its lines where the data put them, and a refused name or folder leaving nothing.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use eenf::trace::{HarmonicPart, SelectedSegment, Trace};
use eenf_figures::*;

/// The first colour of the palette: the first of several series' line.
const BLUE: [u8; 3] = [31, 119, 180];
/// A lone estimate's line.
const RED: [u8; 3] = [255, 0, 0];

/// Width, height and RGB pixels of a PNG written by the figures.
fn png_pixels(path: &Path) -> (u32, u32, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    assert_eq!(info.color_type, png::ColorType::Rgb);
    (info.width, info.height, buf)
}

fn pixels_of(rgb: &[u8], colour: [u8; 3]) -> usize {
    rgb.chunks_exact(3).filter(|p| *p == colour).count()
}

fn not_white(rgb: &[u8]) -> usize {
    rgb.chunks_exact(3)
        .filter(|p| *p != [255, 255, 255])
        .count()
}

/// Draws with `draw` as PNG and SVG into a fresh folder; checks what every figure must be and
/// returns the PNG's pixels and the SVG's text.
fn both(name: &str, title: &str, draw: impl Fn(&Path) -> eenf::Result<()>) -> (Vec<u8>, String) {
    let dir = tempfile::tempdir().unwrap();
    let png_path = dir.path().join(format!("{name}.png"));
    let svg_path = dir.path().join(format!("{name}.svg"));
    draw(&png_path).unwrap();
    draw(&svg_path).unwrap();
    let (w, h, rgb) = png_pixels(&png_path);
    assert_eq!((w, h), (1100, 720), "{name}");
    assert!(
        not_white(&rgb) > 20_000,
        "{name}: {} drawn pixels",
        not_white(&rgb)
    );
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    assert!(svg.starts_with("<svg"), "{name}");
    assert!(svg.contains(title), "{name}: the title is missing");
    // nothing but the two figures: no temporary left behind
    let names: Vec<PathBuf> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
    (rgb, svg)
}

/// A grid-like ENF: a slow swing of ±20 mHz around 50 Hz, one value a second.
fn wander(n: usize) -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let f = t
        .iter()
        .map(|t| 50.0 + 0.02 * (2.0 * PI * t / 200.0).sin())
        .collect();
    (t, f)
}

#[test]
fn a_comparison_draws_the_estimate_and_refuses_other_formats() {
    let (t, reference) = wander(600);
    let estimate: Vec<f64> = reference
        .iter()
        .enumerate()
        .map(|(i, r)| if i % 50 == 7 { f64::NAN } else { r + 0.001 })
        .collect();
    let draw = |p: &Path| {
        plot_comparison(
            p,
            "clip.aedat4 against the mains",
            &t,
            &estimate,
            &reference,
        )
    };
    let (rgb, svg) = both("compare", "clip.aedat4 against the mains", draw);
    // a lone estimate is red, drawn across the whole figure
    assert!(pixels_of(&rgb, RED) > 1500, "{}", pixels_of(&rgb, RED));
    assert!(svg.contains("ENF (Hz)"));

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("notes.txt");
    std::fs::write(&file, "x").unwrap();
    for bad in [dir.path().join("x.jpg"), file.join("x.png")] {
        let err = plot_comparison(&bad, "t", &t, &estimate, &reference).unwrap_err();
        assert!(err.report().contains("x."), "{}", err.report());
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // a folder that does not exist yet is made
    let deeper = dir.path().join("figures/x.svg");
    plot_comparison(&deeper, "t", &t, &estimate, &reference).unwrap();
    assert!(deeper.is_file());
}

#[test]
fn methods_keep_their_colours_and_gaps_break_the_line() {
    let (t, reference) = wander(300);
    let a: Vec<f64> = reference.iter().map(|r| r + 0.002).collect();
    let b: Vec<f64> = reference.iter().map(|r| r - 0.002).collect();
    let series = [
        Series {
            label: "paper".into(),
            time_s: &t,
            estimate: &a,
            reference: &reference,
            colour: 0,
        },
        Series {
            label: "block".into(),
            time_s: &t,
            estimate: &b,
            reference: &reference,
            colour: 1,
        },
    ];
    let (rgb, svg) = both("methods", "two methods", |p| {
        plot_methods(p, "two methods", &series)
    });
    let orange = [255, 127, 14];
    assert!(pixels_of(&rgb, BLUE) > 1000 && pixels_of(&rgb, orange) > 1000);
    assert!(svg.contains("paper") && svg.contains("block"));
    // an estimate with no value at all draws no line of its colour (only its legend's sample)
    let empty = vec![f64::NAN; t.len()];
    let (rgb, _) = both("empty", "nothing", |p| {
        plot_comparison(p, "nothing", &t, &empty, &reference)
    });
    assert!(pixels_of(&rgb, RED) < 200, "{}", pixels_of(&rgb, RED));
}

#[test]
fn an_extraction_shows_each_harmonic_and_the_choice() {
    let (t, f) = wander(240);
    let harmonics = (1..=3)
        .map(|m| HarmonicPart {
            harmonic: m,
            center_hz: 100.0 * m as f64,
            enf_hz: f.iter().map(|v| v + 0.001 * m as f64).collect(),
            snr_db: vec![20.0; f.len()],
        })
        .collect();
    let trace = Trace {
        nominal_hz: Some(50.0),
        step_s: 1.0,
        time_s: t.clone(),
        enf_hz: f.clone(),
        harmonics,
        selected: vec![
            SelectedSegment {
                start_s: 0.0,
                harmonic: 1,
            },
            SelectedSegment {
                start_s: 120.0,
                harmonic: 2,
            },
        ],
        ..Trace::default()
    };
    let (_, svg) = both("trace", "walk.aedat4", |p| {
        plot_extraction(p, "walk.aedat4", &trace)
    });
    assert!(
        svg.contains("100 Hz") || svg.contains("harmonic"),
        "no harmonic labelled"
    );
}

#[test]
fn a_spectrogram_a_summary_a_flicker_map_and_edits_are_drawn() {
    let fs = 1000.0;
    let x: Vec<f64> = (0..20_000)
        .map(|i| (2.0 * PI * 100.02 * i as f64 / fs).sin())
        .collect();
    let s = eenf_dsp::spectrogram(&x, fs, 2.0, 0.5, (99.0, 101.0));
    let line_t: Vec<f64> = s.time_s.clone();
    let line_f = vec![100.02; line_t.len()];
    both("spectrogram", "hum", |p| {
        plot_spectrogram(p, "hum", &s, Some((&line_t, &line_f)), 40.0)
    });

    let classes = vec!["static".to_string(), "walk".to_string()];
    let methods = vec!["paper".to_string()];
    let bars: Vec<SummaryBar> = classes
        .iter()
        .map(|c| SummaryBar {
            class: c.clone(),
            method: "paper".into(),
            method_index: 0,
            cc: 0.95,
            mae_mhz: 2.5,
            paper: Some((0.97, 2.0)),
        })
        .collect();
    both("summary", "bench", |p| {
        plot_summary(p, "bench", &classes, &methods, &bars)
    });

    let map = eenf::flicker_map::FlickerMap {
        width: 64,
        height: 48,
        tile: 16,
        cols: 4,
        rows: 3,
        events: vec![1000; 12],
        strength: (0..12)
            .map(|i| if i == 5 { None } else { Some(i as f64) })
            .collect(),
        whole: None,
        seconds: 10.0,
        damage: None,
    };
    both("map", "a lamp", |p| plot_flicker_map(p, "a lamp", &map));

    // a 40 mHz step half way: the edits figure marks it
    let (t, mut f) = wander(400);
    for v in &mut f[200..] {
        *v += 0.04;
    }
    let trace = Trace {
        nominal_hz: Some(50.0),
        step_s: 1.0,
        time_s: t,
        enf_hz: f,
        ..Trace::default()
    };
    let report =
        eenf::edits::trace_edits(&trace, Path::new("cut.csv"), &Default::default()).unwrap();
    both("edits", "cut.csv", |p| plot_edits(p, "cut.csv", &report));
}

#[test]
fn long_names_are_shortened_in_the_middle_for_titles() {
    let long = Path::new("/data/dvSave-2022_08_17_16_54_30-a-very-long-session-name.aedat4");
    let t = title_name(long);
    assert_eq!(t.chars().count(), 43);
    assert!(t.starts_with("dvSave-2022_08_17") && t.ends_with("name.aedat4") && t.contains('…'));
    assert_eq!(title_name(Path::new("x/short.wav")), "short.wav");
}
