//! Tests of eenf-sim's `scene` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_sim::*;

fn render_all(scene: &Scene, t: f64, n: usize) -> [Vec<f32>; CHANNELS] {
    let mut out: [Vec<f32>; CHANNELS] = std::array::from_fn(|_| vec![0f32; n]);
    scene.render(t, 0, n, &mut out, 0);
    out
}

#[test]
fn a_static_scene_does_not_change_and_lamps_share_the_light() {
    let config = SceneConfig::default();
    let scene = Scene::new(&config, 40, 30, &[1.0, 3.0], 0.2, 1.0, 5);
    let a = render_all(&scene, 0.0, 1200);
    let b = render_all(&scene, 3.7, 1200);
    assert_eq!(a, b);
    assert!(scene.is_static());
    // the shares hold on average, and so does the daylight share
    let mean = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64;
    let ratio = mean(&a[1]) / mean(&a[0]);
    assert!((ratio - 3.0).abs() < 0.2, "{ratio}");
    let lamp = mean(&a[0]) + mean(&a[1]);
    let day = mean(&a[MAX_LAMPS]);
    assert!((day / (lamp + day) - 0.2).abs() < 0.03);
}

#[test]
fn shake_moves_the_view_by_about_its_rms() {
    let config = SceneConfig {
        shake: Some(Shake::default()),
        ..SceneConfig::default()
    };
    let scene = Scene::new(&config, 640, 480, &[1.0], 0.2, 1.0, 2);
    let xs: Vec<f64> = (0..20_000)
        .map(|i| scene.frame(i as f64 * 0.01).pose.dx)
        .collect();
    let rms = (xs.iter().map(|x| x * x).sum::<f64>() / xs.len() as f64).sqrt();
    assert!(rms > 1.2 && rms < 2.7, "rms {rms} px");
    assert!(!scene.is_static());
}

#[test]
fn the_walker_crosses_the_view_and_casts_a_shadow() {
    let config = SceneConfig {
        objects: vec![walker()],
        ..SceneConfig::default()
    };
    let (w, h) = (80, 60);
    let scene = Scene::new(&config, w, h, &[1.0], 0.0, 1.0, 3);
    let empty = Scene::new(&SceneConfig::default(), w, h, &[1.0], 0.0, 1.0, 3);
    let base = render_all(&empty, 0.0, w * h);
    let mut seen = vec![false; w];
    for step in 0..40 {
        let t = step as f64 * 0.25;
        let now = render_all(&scene, t, w * h);
        let row = (0.6 * h as f64) as usize;
        for x in 0..w {
            if now[0][row * w + x] != base[0][row * w + x] {
                seen[x] = true;
            }
        }
    }
    // every column of the body's row is crossed within 10 s
    assert!(seen.iter().all(|&s| s), "{seen:?}");
    // the boxes hold every pixel that changes
    let (t0, t1) = (3.0, 3.25);
    let (a, b) = (render_all(&scene, t0, w * h), render_all(&scene, t1, w * h));
    let boxes = scene.moving_boxes(t0, t1);
    for p in 0..w * h {
        if a[0][p] != b[0][p] {
            let (x, y) = (p % w, p / w);
            assert!(boxes
                .iter()
                .any(|bx| x >= bx.0 && x < bx.2 && y >= bx.1 && y < bx.3));
        }
    }
}
