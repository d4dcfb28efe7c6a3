//! The simulator against the physics it claims: event counts from log-intensity swings, the
//! harmonic ladder of log I, dim light, motion against flicker, readout and determinism.

use std::f64::consts::PI;

use eenf_sim::{
    simulate, Lamp, LampKind, MainsPhase, PixelConfig, Readout, SceneKind, SimConfig, SimStats,
};

/// All events of a run: (t µs from start, x, y, ON).
struct Events {
    t: Vec<i64>,
    x: Vec<u16>,
    y: Vec<u16>,
    p: Vec<bool>,
    stats: SimStats,
}

fn run(config: &SimConfig, mains: &MainsPhase) -> Events {
    let mut e = Events {
        t: vec![],
        x: vec![],
        y: vec![],
        p: vec![],
        stats: SimStats::default(),
    };
    e.stats = simulate(config, mains, |b| {
        e.t.extend(b.t.iter().map(|t| t - config.start_us));
        e.x.extend_from_slice(&b.x);
        e.y.extend_from_slice(&b.y);
        e.p.extend_from_slice(&b.p);
        Ok::<(), ()>(())
    })
    .unwrap();
    e
}

fn steady_50hz(seconds: f64) -> MainsPhase {
    MainsPhase::from_frequency(50.0, &[50.0; 4], 1.0, 0.0, seconds, 0.3)
}

/// A noiseless, ideal pixel: instantaneous photoreceptor, no dark current, equal thresholds.
fn ideal_pixel() -> PixelConfig {
    PixelConfig {
        dark: 0.0,
        threshold_spread: 0.0,
        refractory_us: 0,
        bandwidth_hz: 0.0,
        shot_noise_hz: 0.0,
        leak_hz: 0.0,
        hot_pixel_fraction: 0.0,
        ..PixelConfig::default()
    }
}

fn sinusoid_lamp(depth: f64) -> Vec<Lamp> {
    vec![Lamp {
        kind: LampKind::Sinusoid { depth },
        phase_deg: 0.0,
        share: 1.0,
    }]
}

/// The default fluorescent tube, alone: deep modulation and many harmonics (bursts of events).
fn fluorescent_lamp() -> Vec<Lamp> {
    vec![Lamp {
        kind: LampKind::named("fluorescent").unwrap(),
        phase_deg: 0.0,
        share: 1.0,
    }]
}

/// Amplitude of the line at `f` in `x` sampled at `fs` (one DFT bin at exactly f).
fn line(x: &[f64], f: f64, fs: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let a = 2.0 * PI * f * i as f64 / fs;
        re += v * a.cos();
        im += v * a.sin();
    }
    2.0 * re.hypot(im) / x.len() as f64
}

/// ON minus OFF events per bin of `bin_us`.
fn net_counts(e: &Events, bin_us: i64, seconds: f64) -> Vec<f64> {
    let n = (seconds * 1e6 / bin_us as f64) as usize;
    let mut out = vec![0.0; n];
    for (t, p) in e.t.iter().zip(&e.p) {
        let b = (t / bin_us) as usize;
        if b < n {
            out[b] += if *p { 1.0 } else { -1.0 };
        }
    }
    out
}

#[test]
fn a_static_pixel_fires_as_its_log_swing_and_threshold_predict() {
    let depth = 0.8;
    let seconds = 2.0;
    let config = SimConfig {
        width: 16,
        height: 12,
        duration_s: seconds,
        lamps: sinusoid_lamp(depth),
        ambient: 0.0,
        pixel: ideal_pixel(),
        readout: Readout::Prophesee {
            step_us: 20,
            max_rate_mev_s: 1e3,
        },
        ..SimConfig::default()
    };
    let e = run(&config, &steady_50hz(seconds + 1.0));
    // log swing per flicker cycle, and the events of each polarity it gives on average: the
    // reference trails the signal by a uniformly distributed fraction of C at each turn
    let swing = ((1.0 + depth) / (1.0 - depth)).ln();
    let c = config.pixel.threshold;
    let predicted = swing / c - 1.0;
    // skip the first cycle (the references start anywhere)
    let cycles = (seconds - 0.01) * 100.0;
    let pixels = 16.0 * 12.0;
    let count = |on: bool| {
        e.t.iter()
            .zip(&e.p)
            .filter(|(t, p)| **t >= 10_000 && **p == on)
            .count() as f64
            / pixels
            / cycles
    };
    let (on, off) = (count(true), count(false));
    eprintln!("per cycle: ON {on:.3}, OFF {off:.3}, predicted {predicted:.3}");
    assert!(
        (on - predicted).abs() < 0.1 * predicted,
        "ON {on} vs {predicted}"
    );
    assert!(
        (off - predicted).abs() < 0.1 * predicted,
        "OFF {off} vs {predicted}"
    );
    // a shallower swing, same law
    let shallow = SimConfig {
        lamps: sinusoid_lamp(0.5),
        ..config
    };
    let e = run(&shallow, &steady_50hz(seconds + 1.0));
    let predicted = (3.0f64).ln() / c - 1.0;
    let on = e.p.iter().filter(|p| **p).count() as f64 / pixels / (seconds * 100.0);
    assert!(
        (on - predicted).abs() < 0.1 * predicted,
        "ON {on} vs {predicted}"
    );
}

#[test]
fn the_event_spectrum_follows_the_harmonic_ladder_of_log_intensity() {
    // log(B + A cos ω) = log p + 2 Σ (−1)^(m−1) q^m/m cos mω, so the event rate, which follows
    // d log I / dt, has lines at m·2f_e whose amplitudes fall as q^m
    // (a small threshold keeps the hysteresis of the reference, a square wave of ±C/2 that
    // adds odd lines, well below the signal's third line)
    let a: f64 = 0.6;
    let q = (1.0 - (1.0 - a * a).sqrt()) / a;
    let seconds = 2.0;
    let config = SimConfig {
        width: 12,
        height: 8,
        duration_s: seconds,
        lamps: sinusoid_lamp(a),
        ambient: 0.0,
        pixel: PixelConfig {
            threshold: 0.01,
            ..ideal_pixel()
        },
        readout: Readout::Prophesee {
            step_us: 20,
            max_rate_mev_s: 1e3,
        },
        ..SimConfig::default()
    };
    let e = run(&config, &steady_50hz(seconds + 1.0));
    let fs = 4000.0;
    let x = net_counts(&e, 250, seconds);
    let amps: Vec<f64> = (1..=4).map(|m| line(&x, 100.0 * m as f64, fs)).collect();
    eprintln!("q = {q:.3}; line amplitudes {amps:?}");
    for m in 1..4 {
        assert!(amps[m] < amps[m - 1], "{amps:?}");
    }
    for m in 1..3 {
        let ratio = amps[m] / amps[0];
        let want = q.powi(m as i32);
        assert!(
            (ratio - want).abs() < 0.2 * want,
            "m={} {ratio} vs {want}",
            m + 1
        );
    }
    // and nothing at the mains frequency itself, nor between the harmonics
    assert!(line(&x, 50.0, fs) < 0.02 * amps[0]);
    assert!(line(&x, 150.0, fs) < 0.02 * amps[0]);
}

#[test]
fn dimmer_light_lowers_the_flicker_modulation_monotonically() {
    let seconds = 3.0;
    let mains = steady_50hz(seconds + 1.0);
    let mut last = f64::MAX;
    let mut amps = vec![];
    for illumination in [1.0, 0.1, 0.01, 0.003, 0.001] {
        let config = SimConfig {
            width: 32,
            height: 24,
            duration_s: seconds,
            illumination,
            ..SimConfig::default()
        };
        let e = run(&config, &mains);
        let x = net_counts(&e, 1000, seconds);
        let amp = line(&x, 100.0, 1000.0) / (32.0 * 24.0);
        amps.push((illumination, amp, e.stats.noise_events));
        assert!(amp < last, "{amps:?}");
        last = amp;
    }
    eprintln!("(illumination, 100 Hz net events per pixel per ms, noise events): {amps:?}");
    // night light loses most of the modulation (photoreceptor low-pass, dark current) and its
    // shot noise grows
    assert!(amps[4].1 < 0.5 * amps[0].1, "{amps:?}");
    assert!(amps[4].2 > 20 * amps[0].2.max(1), "{amps:?}");
}

/// Mean over busy milliseconds of the minority polarity's share of the events.
fn mixed_polarity_share(e: &Events, seconds: f64) -> f64 {
    let n = (seconds * 1000.0) as usize;
    let mut on = vec![0u32; n];
    let mut off = vec![0u32; n];
    for (t, p) in e.t.iter().zip(&e.p) {
        let b = (t / 1000) as usize;
        if b < n {
            if *p {
                on[b] += 1
            } else {
                off[b] += 1
            }
        }
    }
    let busy: Vec<f64> = (0..n)
        .filter(|&b| on[b] + off[b] >= 10)
        .map(|b| on[b].min(off[b]) as f64 / (on[b] + off[b]) as f64)
        .collect();
    assert!(busy.len() > 100, "only {} busy ms", busy.len());
    busy.iter().sum::<f64>() / busy.len() as f64
}

#[test]
fn motion_gives_both_polarities_at_once_flicker_mostly_one() {
    let seconds = 2.0;
    let mains = steady_50hz(seconds + 1.0);
    let quiet = PixelConfig {
        shot_noise_hz: 0.0,
        leak_hz: 0.0,
        hot_pixel_fraction: 0.0,
        ..PixelConfig::default()
    };
    let flicker = SimConfig {
        width: 64,
        height: 48,
        duration_s: seconds,
        pixel: quiet.clone(),
        ..SimConfig::default()
    };
    let e = run(&flicker, &mains);
    let flicker_mix = mixed_polarity_share(&e, seconds);
    // the same room under steady light, with a walker and a fan moving through it
    let motion = SimConfig {
        lamps: sinusoid_lamp(0.0),
        pixel: quiet,
        ..flicker.clone()
    }
    .with_kinds(&[SceneKind::DynamicObject]);
    let e = run(&motion, &mains);
    let motion_mix = mixed_polarity_share(&e, seconds);
    eprintln!("minority polarity share: flicker {flicker_mix:.3}, motion {motion_mix:.3}");
    assert!(flicker_mix < 0.1, "{flicker_mix}");
    assert!(motion_mix > 0.2, "{motion_mix}");
}

#[test]
fn camera_shake_and_objects_make_events_without_flicker() {
    let seconds = 1.0;
    let mains = steady_50hz(seconds + 1.0);
    // 160 pixels wide: the default shake (0.3 % of the width RMS) is about half a pixel
    let base = SimConfig {
        width: 160,
        height: 120,
        duration_s: seconds,
        lamps: sinusoid_lamp(0.0),
        pixel: PixelConfig {
            shot_noise_hz: 0.0,
            leak_hz: 0.0,
            hot_pixel_fraction: 0.0,
            ..PixelConfig::default()
        },
        ..SimConfig::default()
    };
    let still = run(&base, &mains).t.len();
    let shaken = run(
        &base.clone().with_kinds(&[SceneKind::DynamicCamera]),
        &mains,
    )
    .t
    .len();
    assert!(
        still < 50,
        "{still} events from a still scene in steady light"
    );
    assert!(shaken > 2000, "{shaken} events from a shaken camera");
}

#[test]
fn the_dvxplorer_readout_groups_events_in_scans_and_has_a_finite_bandwidth() {
    let seconds = 0.5;
    let mains = steady_50hz(seconds + 1.0);
    let fluorescent = fluorescent_lamp();
    let free = SimConfig {
        width: 128,
        height: 96,
        duration_s: seconds,
        lamps: fluorescent,
        ..SimConfig::default()
    };
    let e = run(&free, &mains);
    let mut distinct = e.t.clone();
    distinct.dedup();
    // one timestamp per scan at most, 200 ± 20 µs apart
    assert!(distinct.len() <= (seconds * 5000.0) as usize);
    assert!(distinct.windows(2).all(|w| w[1] - w[0] >= 160));
    assert_eq!(e.stats.dropped_events + e.stats.delayed_events, 0);
    // a readout of 5 M events/s cannot carry this scene's bursts
    let limited = SimConfig {
        readout: Readout::Dvxplorer {
            scan_period_us: 200,
            scan_jitter_us: 20,
            max_rate_mev_s: 5.0,
            fifo_events: 2000,
        },
        ..free.clone()
    };
    let l = run(&limited, &mains);
    assert!(
        l.stats.delayed_events > 0 && l.stats.dropped_events > 0,
        "{:?}",
        l.stats
    );
    // the readout loses no event silently: each is written or counted as dropped
    assert_eq!(l.stats.events + l.stats.dropped_events, e.stats.events);
    let mut per_scan = std::collections::HashMap::new();
    for t in &l.t {
        *per_scan.entry(*t).or_insert(0usize) += 1;
    }
    assert!(
        per_scan.values().all(|&n| n <= 1000),
        "a scan holds at most 5e6 × 200 µs events"
    );
    // Prophesee: µs timestamps, in order, and far more distinct times
    let p = run(
        &SimConfig {
            readout: Readout::prophesee(),
            ..free
        },
        &mains,
    );
    assert!(p.t.windows(2).all(|w| w[1] >= w[0]));
    let mut pd = p.t.clone();
    pd.dedup();
    assert!(
        pd.len() > 4 * distinct.len(),
        "{} vs {}",
        pd.len(),
        distinct.len()
    );
}

#[test]
fn the_dvs128_arbiter_serves_one_event_at_a_time_at_its_bus_rate() {
    let seconds = 0.5;
    let mains = steady_50hz(seconds + 1.0);
    let fluorescent = fluorescent_lamp();
    let scene = SimConfig {
        width: 64,
        height: 48,
        duration_s: seconds,
        lamps: fluorescent,
        readout: Readout::prophesee(),
        ..SimConfig::default()
    };
    let p = run(&scene, &mains);
    let d = run(
        &SimConfig {
            readout: Readout::dvs128(),
            ..scene.clone()
        },
        &mains,
    );
    // the same pixels fire; the arbiter drops nothing, it only spreads bursts out
    assert_eq!(d.t.len(), p.t.len());
    assert_eq!(d.stats.dropped_events, 0);
    // no two events share a timestamp: each is at least one bus cycle (1 µs) after the last
    assert!(d.t.windows(2).all(|w| w[1] > w[0]));
    let mut shared = p.t.clone();
    shared.dedup();
    assert!(shared.len() < p.t.len(), "the Prophesee readout shares µs");
    // a slower bus delays the flicker's bursts further: 0.1 M events/s is 10 µs an event
    let slow = run(
        &SimConfig {
            readout: Readout::Dvs128 {
                step_us: 50,
                max_rate_mev_s: 0.1,
            },
            ..scene
        },
        &mains,
    );
    assert!(slow.t.windows(2).all(|w| w[1] - w[0] >= 10));
}

#[test]
fn a_person_walking_makes_no_spectral_line_near_the_flicker() {
    // a constant pace repeats its pixel crossings so exactly that they make lines near
    // 100–120 Hz; a person's irregular pace must not (nothing here flickers)
    let seconds = 20.0;
    let mains = steady_50hz(seconds + 1.0);
    let mut config = SimConfig {
        width: 32,
        height: 32,
        duration_s: seconds,
        lamps: sinusoid_lamp(0.0),
        readout: Readout::prophesee(),
        ..SimConfig::default()
    }
    .with_kinds(&[SceneKind::LampSpot]);
    let e = run(&config, &mains);
    assert!(e.t.len() > 20_000, "{} events", e.t.len());
    let x = net_counts(&e, 1000, seconds);
    let strongest = |x: &[f64]| {
        (0..=600)
            .map(|k| line(x, 90.0 + 0.05 * k as f64, 1000.0))
            .fold(0.0f64, f64::max)
    };
    let floor = (0..200)
        .map(|k| line(&x, 140.0 + 0.3 * k as f64, 1000.0))
        .sum::<f64>()
        / 200.0;
    let walk = strongest(&x);
    assert!(walk < 6.0 * floor, "a line {:.1}x the floor", walk / floor);
    // the machine's constant pace does make one
    config.scene.objects = vec![eenf_sim::walker()];
    let m = net_counts(&run(&config, &mains), 1000, seconds);
    let machine = strongest(&m);
    assert!(machine > 6.0 * floor, "{:.1}x the floor", machine / floor);
}

#[test]
fn the_same_seed_gives_the_same_recording_on_any_number_of_threads() {
    let seconds = 1.0;
    let mains = steady_50hz(seconds + 1.0);
    let config = SimConfig {
        width: 96,
        height: 64,
        duration_s: seconds,
        seed: 42,
        ..SimConfig::default()
    }
    .with_kinds(&[SceneKind::DynamicObject, SceneKind::DynamicCamera]);
    let a = run(&config, &mains);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = pool.install(|| run(&config, &mains));
    assert!(a.t.len() > 1000);
    assert_eq!(a.t, b.t);
    assert_eq!(a.x, b.x);
    assert_eq!(a.y, b.y);
    assert_eq!(a.p, b.p);
    let c = run(&SimConfig { seed: 43, ..config }, &mains);
    assert_ne!(a.x, c.x);
}
