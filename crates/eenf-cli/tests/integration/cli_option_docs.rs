//! The option sets' help, written once as the flags' doc comments, reaches Python and the
//! page through `eenf::options::DOCS_JSON`; this keeps that file equal to the flags, and
//! checks that every flag's name and default is one the library's option set takes.
//! `EENF_BLESS=1 cargo test --release -p eenf-cli option_docs` rewrites the file.

use eenf::options::{self, OptionSet};

const DOCS_FILE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../eenf/src/options/docs.json");

#[test]
fn option_docs_match_the_flags() {
    let want = serde_json::to_string_pretty(&eenf_cli::args::option_docs()).unwrap() + "\n";
    if std::env::var_os("EENF_BLESS").is_some() {
        std::fs::write(DOCS_FILE, &want).unwrap();
    }
    assert!(
        options::DOCS_JSON == want,
        "{DOCS_FILE} differs from the flags' help: run EENF_BLESS=1 cargo test --release -p eenf-cli option_docs"
    );
    // the help that Python and the page show names options as they take them, not as flags
    assert!(!want.contains("--"), "a flag in the options' help");
    assert!(
        want.contains("more than max_gap"),
        "the help's flags are library names"
    );
}

/// The library's sets behind each documented set.
fn library_sets(name: &str) -> Vec<Box<dyn OptionSet>> {
    match name {
        "input" => vec![Box::new(options::InputSettings::default())],
        "extract" => vec![Box::new(options::ExtractSettings::default())],
        "reference" => vec![
            Box::new(options::AudioSettings::default()),
            Box::new(options::TrackerSettings::default()),
        ],
        "video" => vec![Box::new(options::VideoSettings::default())],
        "simulate" => vec![Box::new(options::SimulateSettings::default())],
        "simulate_dataset" => vec![Box::new(options::DatasetSettings::default())],
        "match" => vec![Box::new(options::MatchSettings::default())],
        "write" => vec![Box::new(options::EventOutputSettings::default())],
        "edits" => vec![Box::new(options::EditSettings::default())],
        "refdb_build" => vec![Box::new(options::StoreInputSettings::default())],
        other => panic!("no library set for {other}"),
    }
}

#[test]
fn every_flag_is_an_option_of_the_library_with_the_same_default() {
    let docs = eenf_cli::args::option_docs();
    let mut checked = 0;
    for (set, opts) in docs.as_object().unwrap() {
        for o in opts.as_array().unwrap() {
            let name = o["name"].as_str().unwrap();
            let mut sets = library_sets(set);
            // the flag's default, given by name, leaves each set as its own default does
            let value = match &o["default"] {
                _ if o["switch"] == true => serde_json::json!(false),
                serde_json::Value::String(d) => serde_json::json!(d),
                _ => serde_json::Value::Null,
            };
            let json = serde_json::json!({ name: value }).to_string();
            {
                let mut refs: Vec<&mut dyn OptionSet> = sets
                    .iter_mut()
                    .map(|b| -> &mut dyn OptionSet { &mut **b })
                    .collect();
                options::apply_json(&mut refs, &json)
                    .unwrap_or_else(|e| panic!("{set}: {name} = {value}: {e}"));
            }
            let after: Vec<String> = sets.iter().map(|s| format!("{s:?}")).collect();
            let fresh: Vec<String> = library_sets(set).iter().map(|s| format!("{s:?}")).collect();
            assert_eq!(
                after, fresh,
                "{set}: the flag's default of {name} is not the library's"
            );
            checked += 1;
        }
    }
    assert!(checked > 60, "{checked} options checked");
    // a name no set has, a value out of range, and a value of the wrong type are refused by name
    let mut s = options::ExtractSettings::default();
    let e = options::apply_json(&mut [&mut s], r#"{"windoww": 8}"#).unwrap_err();
    assert_eq!(e, options::OptionError::Unknown("windoww".into()));
    let e = options::apply_json(&mut [&mut s], r#"{"window": -1}"#).unwrap_err();
    assert_eq!(e.option(), Some("window"));
    assert!(e.to_string().contains("-1 is outside 0.01..=3600"), "{e}");
    let e = options::apply_json(&mut [&mut s], r#"{"harmonics": "many"}"#).unwrap_err();
    assert_eq!(e.option(), Some("harmonics"));
}
