//! Tests of eenf's `dataset` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::dataset::*;
use eenf::time::LocalTime;
use eenf_sim::{Readout, SceneKind};
use std::path::Path;

#[test]
fn the_lamp_spot_preset_has_ten_recordings_per_camera() {
    let spec = DatasetSpec {
        preset: "lamp-spot".into(),
        duration_s: None,
        resolution: None,
        readout: Readout::dvxplorer(),
        tz_s: 0.0,
        seed: 7,
    };
    let (plans, duration) = plan_dataset(&spec, (0.0, 6.0 * 3600.0)).unwrap();
    assert_eq!((plans.len(), duration), (80, 40.0));
    for c in &LAMP_SPOT_CLASSES {
        let of: Vec<_> = plans.iter().filter(|p| p.class == c.name).collect();
        assert_eq!(of.len(), LAMP_SPOT_SEEDS, "{}", c.name);
        for p in of {
            let cfg = &p.config;
            assert_eq!((cfg.width, cfg.height), (c.side, c.side));
            assert_eq!(cfg.readout, (c.readout)());
            assert_eq!(cfg.kinds, vec![SceneKind::LampSpot]);
            let gain = cfg.scene.bulb.as_ref().unwrap().gain;
            assert!((c.gain.0..=c.gain.1).contains(&gain), "{gain}");
        }
    }
    assert!(scored_against_truth("lamp-spot") && !scored_against_truth("small"));
}

#[test]
fn parses_dataset_names() {
    let t = recording_start(Path::new("static/dvSave-2022_08_17_16_54_30.aedat4")).unwrap();
    assert_eq!((t.hour(), t.second_of_hour()), (16, 54 * 60 + 30));
    assert_eq!(t.date(), "2022_08_17");
    assert!(recording_start(Path::new("dvSave-2022_13_17_16_54_30.aedat4")).is_none());
    let r = reference_hour(Path::new("x/2022_08_17_Wed_17_00_00.wav")).unwrap();
    assert_eq!((r.day(), r.hour(), r.minute()), (17, 17, 0));
    assert!(reference_hour(Path::new("notes.wav")).is_none());
    // names made from times read back as those times
    let t = LocalTime::from_local_seconds(r.local_seconds() + 754);
    assert_eq!(
        recording_name(&t, "aedat4"),
        "dvSave-2022_08_17_17_12_34.aedat4"
    );
    assert_eq!(reference_name(&t), "2022_08_17_Wed_17_00_00.wav");
}
