//! The grid type (`eenf_core::Grid`, `Nominal`): only 50 and 60 Hz stand for a grid.

use eenf_core::{Grid, Nominal};

#[test]
fn only_fifty_and_sixty_hertz_are_grids() {
    assert_eq!(Grid::of_hz(50.0), Some(Grid::Hz50));
    assert_eq!(Grid::of_hz(60.0), Some(Grid::Hz60));
    for hz in [0.0, 47.0, 50.5, 55.0, 59.99, f64::NAN, f64::INFINITY] {
        assert_eq!(Grid::of_hz(hz), None, "{hz}");
    }
    assert_eq!("60".parse::<Grid>(), Ok(Grid::Hz60));
    assert!("47".parse::<Grid>().is_err());
    assert_eq!(Grid::Hz50.to_string(), "50");
}

#[test]
fn a_mean_names_the_grid_it_lies_within_a_hertz_of() {
    assert_eq!(Grid::near(49.3), Some(Grid::Hz50));
    assert_eq!(Grid::near(60.8), Some(Grid::Hz60));
    assert_eq!(Grid::near(55.0), None);
    assert_eq!(Grid::near(61.2), None);
    assert_eq!(Grid::near(f64::NAN), None);
}

#[test]
fn a_nominal_leaves_open_the_grids_it_does_not_name() {
    assert_eq!(Nominal::Auto.grids(), &[Grid::Hz50, Grid::Hz60]);
    assert_eq!(
        "50".parse::<Nominal>().map(Nominal::grids),
        Ok(&[Grid::Hz50][..])
    );
    assert_eq!("60".parse::<Nominal>().map(Nominal::hz), Ok(Some(60.0)));
    assert_eq!("auto".parse::<Nominal>().map(Nominal::grid), Ok(None));
    // a number that is no grid is refused where it is read, not mapped to the nearest
    assert!("55".parse::<Nominal>().is_err());
    assert!("50.0".parse::<Nominal>().is_err());
}

#[test]
fn a_trace_off_both_grids_is_refused_for_matching() {
    let t = eenf::trace::Trace::new(1.0, vec![55.0; 30]);
    let e = eenf::locate::match_grid(&t, std::path::Path::new("t.csv")).unwrap_err();
    assert!(
        e.report().contains("neither a 50 nor a 60 Hz grid"),
        "{}",
        e.report()
    );
    let t = eenf::trace::Trace::new(1.0, vec![59.98; 30]);
    assert_eq!(
        eenf::locate::match_grid(&t, std::path::Path::new("t.csv")).ok(),
        Some(Grid::Hz60)
    );
}
