//! V-ENF against videos rendered by the simulator's frame camera, whose ENF is known.

mod common;

use std::io::Write;

use eenf_dsp::agreement;
use eenf_sim::{CameraConfig, MainsPhase, SimConfig, SyntheticEnf};
use eenf_video::{
    strongest_line, video_enf, FrameSource, IdleRows, RowMeans, RowSampling, VideoError,
    VideoOptions, Y4mWriter,
};

/// Renders `seconds` of a static scene through `camera` into a Y4M file.
fn render(camera: &CameraConfig, seconds: f64, seed: u64) -> (tempfile::TempPath, MainsPhase) {
    let config = SimConfig {
        duration_s: seconds,
        seed,
        ..SimConfig::default()
    };
    let mains = MainsPhase::synthetic(50.0, seconds + 1.0, SyntheticEnf::default(), seed);
    (common::write_y4m(&config, camera, &mains), mains)
}

#[test]
fn zero_padded_rows_recover_the_enf_of_a_static_scene() {
    // a webcam with its anti-flicker setting off and a 25 ms exposure (2.5 flicker periods)
    let mut camera = CameraConfig::lr().scaled(0.25);
    camera.anti_flicker = false;
    camera.exposure_s = 0.025;
    let seconds = 60.0;
    let (path, mains) = render(&camera, seconds, 3);
    let mut source = FrameSource::open(&path).unwrap();
    let opts = VideoOptions {
        sampling: RowSampling::ZeroPad(IdleRows::ReadoutS(camera.readout_s)),
        ..VideoOptions::default()
    };
    let trace = video_enf(&mut source, &opts, |_| {}).unwrap();
    assert_eq!(trace.nominal_hz, 50.0, "grid detected from the flicker");
    let truth = mains.truth(seconds);
    let a = agreement(&trace.enf_hz, &truth).unwrap();
    println!(
        "LR/4 zero-padded (L = {:?}): CC {:.4}, MAE {:.2} mHz over {} s",
        trace.virtual_rows,
        a.cc,
        a.mae_hz * 1e3,
        a.n
    );
    assert!(a.cc >= 0.95, "CC {}", a.cc);
    assert!(a.mae_hz < 0.005, "MAE {}", a.mae_hz);
    // the idle rows estimated from the ripple serve as well as the known readout
    let mut source = FrameSource::open(&path).unwrap();
    let auto = video_enf(&mut source, &VideoOptions::default(), |_| {}).unwrap();
    let b = agreement(&auto.enf_hz, &truth).unwrap();
    println!(
        "auto idle: L = {:?} (true {:.1}): CC {:.4}",
        auto.virtual_rows,
        camera.virtual_rows(),
        b.cc
    );
    assert!(b.cc >= 0.95, "CC {}", b.cc);
}

/// RMS of the row means after the paper's scene removal.
fn ripple_rms(path: &std::path::Path) -> f64 {
    let mut source = FrameSource::open(path).unwrap();
    let rows = RowMeans::read(&mut source, |_| {})
        .unwrap()
        .without_scene(eenf_video::SceneRemoval::Paper);
    (rows.values.iter().map(|v| v * v).sum::<f64>() / rows.values.len() as f64).sqrt()
}

#[test]
fn anti_flicker_exposure_nulls_the_ripple_as_the_box_filter_predicts() {
    // the same webcam with a free 25 ms exposure and with its anti-flicker setting (30 ms,
    // three flicker periods): a box filter of length T passes the 2f line with gain
    // |sinc(2f·T)|, 0.127 at 25 ms and ~0 at 30 ms, so only the noise is left
    let mut free = CameraConfig::lr().scaled(0.25);
    free.anti_flicker = false;
    free.exposure_s = 0.025;
    let locked = CameraConfig::lr().scaled(0.25);
    assert!((locked.exposure_on(50.0) - 0.030).abs() < 1e-12);
    let (a, _) = render(&free, 8.0, 7);
    let (b, _) = render(&locked, 8.0, 7);
    let (ra, rb) = (ripple_rms(&a), ripple_rms(&b));
    // what the locked camera keeps is mostly its noise (shot, read, 8-bit steps)
    println!("ripple rms: free 25 ms {ra:.4}, anti-flicker 30 ms {rb:.4} (of 255)");
    assert!(ra > 5.0 * rb, "anti-flicker left {rb} of {ra}");
}

#[test]
fn naive_concatenation_moves_the_line_as_the_rolling_shutter_model_predicts() {
    // a long idle gap (readout 20 ms of the 33 ms period): the frame-to-frame phase step
    // c = 2f(1 − rows/L)/fps puts naive sampling's strongest line at 2f − round(c)·fps
    let mut camera = CameraConfig::hr().scaled(0.1);
    camera.readout_s = 0.020;
    camera.exposure_s = 0.002;
    let (path, _) = render(&camera, 20.0, 5);
    let mut source = FrameSource::open(&path).unwrap();
    let rows = RowMeans::read(&mut source, |_| {})
        .unwrap()
        .without_scene(eenf_video::SceneRemoval::Paper);
    let l = camera.virtual_rows();
    let c = 100.0 * (1.0 - camera.height as f64 / l) / camera.fps;
    let predicted = 100.0 - c.round() * camera.fps;
    let naive = strongest_line(&rows, RowSampling::Naive, None, 40.0, 160.0);
    let padded = strongest_line(
        &rows,
        RowSampling::ZeroPad(IdleRows::VirtualRows(l)),
        Some(l),
        40.0,
        160.0,
    );
    println!("c = {c:.3}: naive line {naive:.2} Hz (predicted {predicted:.2}), zero-padded {padded:.2} Hz");
    assert!(c.round() >= 1.0, "the test needs a shifted line (c = {c})");
    assert!((naive - predicted).abs() < 0.3, "naive line at {naive} Hz");
    assert!(
        (padded - 100.0).abs() < 0.3,
        "zero-padded line at {padded} Hz"
    );
}

#[test]
fn bad_videos_get_clear_errors() {
    let (w, h) = (32usize, 24usize);
    let mut good = Vec::new();
    {
        let mut out = Y4mWriter::new(&mut good, w, h, 30.0).unwrap();
        for k in 0..30 {
            out.write_frame(&vec![(k * 3) as u8; w * h]).unwrap();
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        std::fs::File::create(&p).unwrap().write_all(bytes).unwrap();
        p
    };
    let read_all = |p: &std::path::Path| -> Result<usize, VideoError> {
        let mut s = FrameSource::open(p)?;
        let mut n = 0;
        while s.next_frame()?.is_some() {
            n += 1;
        }
        Ok(n)
    };
    assert_eq!(read_all(&write("good.y4m", &good)).unwrap(), 30);
    // cut in the middle of frame 11
    let cut = write("cut.y4m", &good[..good.len() / 3 + 100]);
    let e = read_all(&cut).unwrap_err().to_string();
    assert!(e.contains("cut.y4m") && e.contains("truncated"), "{e}");
    // a frame marker overwritten
    let mut corrupt = good.clone();
    let second = corrupt.windows(5).rposition(|x| x == b"FRAME").unwrap();
    corrupt[second..second + 5].copy_from_slice(b"XXXXX");
    let e = read_all(&write("corrupt.y4m", &corrupt))
        .unwrap_err()
        .to_string();
    assert!(e.contains("corrupt.y4m") && e.contains("FRAME"), "{e}");
    // a header that promises absurd frames
    let e = read_all(&write(
        "huge.y4m",
        b"YUV4MPEG2 W100000 H100000 F30:1 Cmono\nFRAME\n",
    ))
    .unwrap_err()
    .to_string();
    assert!(e.contains("huge.y4m") && e.contains("exceeds"), "{e}");
    let e = read_all(&write("empty.y4m", b"")).unwrap_err().to_string();
    assert!(e.contains("empty"), "{e}");

    // not a Y4M: ffmpeg is needed, and here it is missing
    std::env::set_var("EENF_FFPROBE", "/nonexistent/ffprobe");
    let e = read_all(&write("clip.mp4", b"\x00\x00\x00\x18ftypmp42 not really"))
        .unwrap_err()
        .to_string();
    std::env::remove_var("EENF_FFPROBE");
    assert!(e.contains("clip.mp4") && e.contains("not installed"), "{e}");

    // a steady picture: no flicker to track
    let mut still = Vec::new();
    {
        let mut out = Y4mWriter::new(&mut still, w, h, 30.0).unwrap();
        let mut x = 7u32;
        for _ in 0..30 * 20 {
            let frame: Vec<u8> = (0..w * h)
                .map(|_| {
                    x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
                    120 + ((x >> 16) % 5) as u8
                })
                .collect();
            out.write_frame(&frame).unwrap();
        }
    }
    let p = write("still.y4m", &still);
    let mut s = FrameSource::open(&p).unwrap();
    let e = video_enf(&mut s, &VideoOptions::default(), |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("no flicker") || e.contains("neither"), "{e}");
}
