//! V-ENF at the frame rates people record at: the simulator's cameras (global and rolling
//! shutter) at 24–240 fps on 50 and 60 Hz grids, whose ENF is known.

mod common;

use eenf_dsp::agreement;
use eenf_sim::{CameraConfig, Lamp, LampKind, MainsPhase, SimConfig, SyntheticEnf};
use eenf_video::{frame_half_band, video_enf, FrameSource, RowSampling, VideoOptions};

/// A small camera at `fps`: global shutter when `readout_s` is 0, a 1/240 s exposure (which
/// keeps most of the flicker), no anti-flicker setting.
fn camera(fps: f64, readout_s: f64) -> CameraConfig {
    let mut c = CameraConfig::lr();
    c.name = "custom".into();
    (c.width, c.height) = (32, 24);
    c.fps = fps;
    c.readout_s = readout_s;
    c.exposure_s = 1.0 / 240.0;
    c.anti_flicker = false;
    c.frame_jitter_s = 0.0;
    c
}

/// A room lit by one incandescent lamp (halogen and filament lamps flicker at 2f alone).
fn incandescent(seconds: f64, seed: u64) -> SimConfig {
    SimConfig {
        duration_s: seconds,
        seed,
        lamps: vec![Lamp {
            kind: LampKind::named("incandescent").unwrap(),
            ..SimConfig::default().lamps[0]
        }],
        ..SimConfig::default()
    }
}

/// Renders `seconds` through `camera` on a `grid` Hz grid into a Y4M file.
fn render(
    camera: &CameraConfig,
    grid: f64,
    seconds: f64,
    seed: u64,
) -> (tempfile::TempPath, MainsPhase) {
    let config = incandescent(seconds, seed);
    let mains = MainsPhase::synthetic(grid, seconds + 1.0, SyntheticEnf::default(), seed);
    (common::write_y4m(&config, camera, &mains), mains)
}

/// The CC and MAE (mHz) of `eenf video` with `sampling` against the truth, or its refusal.
fn traced(
    path: &std::path::Path,
    mains: &MainsPhase,
    seconds: f64,
    sampling: Option<RowSampling>,
) -> Result<(f64, f64, RowSampling), String> {
    let mut source = FrameSource::open(path).unwrap();
    let mut opts = VideoOptions::default();
    if let Some(s) = sampling {
        opts.sampling = s;
    }
    let t = video_enf(&mut source, &opts, |_| {}).map_err(|e| e.to_string())?;
    let a = agreement(&t.enf_hz, &mains.truth(seconds)).unwrap();
    Ok((a.cc, a.mae_hz * 1e3, t.sampling))
}

#[test]
fn a_gopro_at_29_97_fps_on_a_50_hz_grid_is_traced_by_its_frames() {
    // global shutter, frame means only: the 100 Hz flicker aliases to 10.09 Hz
    let seconds = 600.0;
    let cam = camera(30000.0 / 1001.0, 0.0);
    let (path, mains) = render(&cam, 50.0, seconds, 11);
    let (cc, mae, used) = traced(&path, &mains, seconds, None).unwrap();
    println!(
        "29.97 fps, global shutter, 50 Hz, 10 min, defaults: CC {cc:.4}, MAE {mae:.2} mHz, {used}"
    );
    assert_eq!(used, RowSampling::Global, "auto takes the frames");
    assert!(cc >= 0.95, "CC {cc}");
    assert!(mae < 2.0, "MAE {mae} mHz");
}

#[test]
fn frame_sampling_is_refused_where_the_alias_sits_on_a_fold() {
    let p = eenf_dsp::EnfParams::default();
    // 25 fps on 50 Hz: the alias is 0 Hz; 29.97 on 60 Hz: 0.12 Hz; 240 fps on 60 Hz:
    // the Nyquist frequency itself
    for (grid, fps) in [(50.0, 25.0), (60.0, 30000.0 / 1001.0), (60.0, 240.0)] {
        let e = frame_half_band(grid, fps, &p).unwrap_err();
        assert!(e.contains("too close to track"), "{e}");
    }
    for (grid, fps) in [
        (50.0, 30000.0 / 1001.0),
        (50.0, 24.0),
        (60.0, 25.0),
        (60.0, 50.0),
    ] {
        let hb = frame_half_band(grid, fps, &p).unwrap();
        assert!(
            hb > 0.6 && hb <= p.half_band_hz,
            "{grid} Hz at {fps} fps: {hb}"
        );
    }
    // a 2-minute 25 fps global-shutter video on 50 Hz: the frames cannot see the flicker
    let (path, mains) = render(&camera(25.0, 0.0), 50.0, 120.0, 3);
    let e = traced(&path, &mains, 120.0, Some(RowSampling::Global)).unwrap_err();
    assert!(e.contains("aliases to 0.00 Hz"), "{e}");
}

/// The table of `docs/video.md`: every frame rate × grid, by rows (a rolling shutter read
/// out over 80 % of the frame period, zero-padded), by frames (a global shutter) and with the
/// defaults (`auto`) on each, two minutes each. Frames trace exactly where
/// [`frame_half_band`] says the alias leaves room, and `auto` never returns a wrong trace.
/// Prints the table: `cargo test --release -p eenf-video --test frame_rates -- --ignored
/// --nocapture`.
#[test]
#[ignore = "renders 36 two-minute videos (run by .ci/run)"]
fn frame_rate_table() {
    let seconds = 120.0;
    let p = eenf_dsp::EnfParams::default();
    println!("| fps | grid | rolling shutter: by rows | rolling shutter: auto | global shutter: by frames | global shutter: auto |");
    println!("|---|---|---|---|---|---|");
    let cell = |r: &Result<(f64, f64, RowSampling), String>, named: bool| match r {
        Ok((cc, mae, used)) if named => format!("{used}: CC {cc:.3}, MAE {mae:.1} mHz"),
        Ok((cc, mae, _)) => format!("CC {cc:.3}, MAE {mae:.1} mHz"),
        Err(_) => "refused".into(),
    };
    let mut wrong = Vec::new();
    for fps in [
        24.0,
        25.0,
        30000.0 / 1001.0,
        30.0,
        50.0,
        60000.0 / 1001.0,
        60.0,
        120.0,
        240.0,
    ] {
        for grid in [50.0, 60.0] {
            let zero_pad = Some(RowSampling::ZeroPad(eenf_video::IdleRows::Auto));
            let (path, mains) = render(&camera(fps, 0.8 / fps), grid, seconds, 5);
            let rows = traced(&path, &mains, seconds, zero_pad);
            let rows_auto = traced(&path, &mains, seconds, None);
            let (path, mains) = render(&camera(fps, 0.0), grid, seconds, 5);
            let frames = traced(&path, &mains, seconds, Some(RowSampling::Global));
            let frames_auto = traced(&path, &mains, seconds, None);
            println!(
                "| {fps:.3} | {grid} Hz | {} | {} | {} | {} |",
                cell(&rows, false),
                cell(&rows_auto, true),
                cell(&frames, false),
                cell(&frames_auto, true)
            );
            let room = frame_half_band(grid, fps, &p).is_ok();
            let good =
                |r: &Result<(f64, f64, RowSampling), String>| r.as_ref().is_ok_and(|t| t.0 >= 0.95);
            let bad =
                |r: &Result<(f64, f64, RowSampling), String>| r.as_ref().is_ok_and(|t| t.0 < 0.9);
            // frames trace exactly where the alias leaves room, and then auto does too
            if room != good(&frames) || (room && !good(&frames_auto)) {
                wrong.push(format!(
                    "{fps} fps, {grid} Hz: frames {frames:?}, auto {frames_auto:?}"
                ));
            }
            // auto traces what the rows trace, and gives no wrong trace of a rolling shutter
            if (good(&rows) && !good(&rows_auto)) || bad(&rows_auto) {
                wrong.push(format!(
                    "{fps} fps, {grid} Hz: rows {rows:?}, auto {rows_auto:?}"
                ));
            }
            // nor of a global shutter whose alias sits on a fold (its rows, all exposed at
            // once, cannot tell the line from its mirror: 240 fps on 60 Hz)
            if bad(&frames_auto) {
                wrong.push(format!("{fps} fps, {grid} Hz: auto gave {frames_auto:?}"));
            }
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// Runs ffmpeg with `args`, failing the test with its message.
fn ffmpeg(args: &[&str]) {
    let out = std::process::Command::new("ffmpeg")
        .args(["-v", "error", "-y"])
        .args(args)
        .output()
        .expect("ffmpeg is installed");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
#[ignore = "needs the ffmpeg program (run by .ci/run)"]
fn a_variable_frame_rate_mp4_is_traced_as_well_as_its_constant_rate_twin() {
    // a global shutter at 120 fps, 10 minutes; the twins keep 1 frame in 4 (30 fps) or each
    // frame with a chance of 1 in 4 (ffmpeg's seeded random: 30 fps on average, 8 ms to a
    // fraction of a second apart), with their times
    let seconds = 600.0;
    let (y4m, mains) = render(&camera(120.0, 0.0), 50.0, seconds, 21);
    let dir = tempfile::tempdir().unwrap();
    let (cfr, vfr) = (dir.path().join("cfr.mp4"), dir.path().join("vfr.mp4"));
    let input = y4m.to_str().unwrap();
    for (select, out) in [("not(mod(n,4))", &cfr), ("lt(random(0),0.25)", &vfr)] {
        let filter = format!("select='{select}'");
        ffmpeg(&[
            "-i",
            input,
            "-vf",
            &filter,
            "-fps_mode",
            "vfr",
            "-c:v",
            "libx264",
            "-crf",
            "12",
            "-pix_fmt",
            "yuv420p",
            out.to_str().unwrap(),
        ]);
    }
    let run = |path: &std::path::Path| {
        let mut source = FrameSource::open(path).unwrap();
        let t = video_enf(&mut source, &VideoOptions::default(), |_| {}).unwrap();
        let a = agreement(&t.enf_hz, &mains.truth(seconds)).unwrap();
        (a.cc, a.mae_hz * 1e3, t.frame_times, t.info.fps)
    };
    let (cc_c, mae_c, times_c, fps_c) = run(&cfr);
    let (cc_v, mae_v, times_v, fps_v) = run(&vfr);
    println!("constant 30 fps: CC {cc_c:.4}, MAE {mae_c:.2} mHz; variable ({fps_v:.3} fps on average): CC {cc_v:.4}, MAE {mae_v:.2} mHz");
    assert!(!times_c && (fps_c - 30.0).abs() < 1e-6, "{fps_c}");
    assert!(times_v, "the variable-rate file's frame times are read");
    assert!(cc_c >= 0.95 && cc_v >= 0.95, "CC {cc_c}, {cc_v}");
    assert!(
        cc_v >= cc_c - 0.01 && mae_v <= mae_c + 0.5,
        "VFR {cc_v}/{mae_v} vs CFR {cc_c}/{mae_c}"
    );
    // read as if evenly spaced, the variable-rate frames give no trace, or a wrong one
    let mut source = FrameSource::open(&vfr).unwrap();
    let mut rows = eenf_video::RowMeans::read(&mut source, |_| {}).unwrap();
    rows.frame_times = None;
    let even = eenf_video::video_enf_from_rows(&rows, &VideoOptions::default());
    let cc_even = even
        .map(|t| agreement(&t.enf_hz, &mains.truth(seconds)).map_or(0.0, |a| a.cc))
        .unwrap_or(0.0);
    println!("the variable-rate frames taken as evenly spaced: CC {cc_even:.3}");
    assert!(cc_even < 0.5, "{cc_even}");
}
