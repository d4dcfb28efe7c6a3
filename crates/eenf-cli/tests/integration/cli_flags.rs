//! One vocabulary of flags, read from the commands' own `--help`: `--json` is a switch
//! everywhere, every `--nominal` takes `auto`, a CSV's value step is `--index-step` wherever
//! one is asked, and every flag the README shows exists on its command.

use std::collections::BTreeMap;
use std::path::Path;

use crate::cli;

/// An option of a command, as its `--help` lists it.
#[derive(Debug)]
struct Flag {
    long: String,
    short: Option<char>,
    takes_value: bool,
    help: String,
}

fn help(cmd: &[&str]) -> String {
    let mut args = cmd.to_vec();
    args.push("--help");
    cli::ok(&args, Path::new("."))
}

/// The options of `eenf CMD --help`, with the text of each (continuation lines included).
fn flags(cmd: &[&str]) -> Vec<Flag> {
    let mut out: Vec<Flag> = Vec::new();
    for line in help(cmd).lines() {
        let t = line.trim_start();
        let (short, rest) = match t.strip_prefix('-') {
            Some(r) if r.len() > 2 && r.as_bytes()[1] == b',' => {
                (r.chars().next(), r[2..].trim_start())
            }
            _ => (None, t),
        };
        if let Some(rest) = rest.strip_prefix("--") {
            let name_end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
                .unwrap_or(rest.len());
            out.push(Flag {
                long: rest[..name_end].to_string(),
                short,
                takes_value: rest[name_end..].starts_with(" <"),
                help: rest[name_end..].to_string(),
            });
        } else if let Some(last) = out.last_mut() {
            last.help.push(' ');
            last.help.push_str(t);
        }
    }
    out
}

/// Every command (`refdb build` and `refdb info` as two), by its words.
fn commands() -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let parse = |prefix: &[&str]| {
        let text = help(prefix);
        let list = text
            .split("Commands:")
            .nth(1)
            .and_then(|s| s.split("Options:").next())
            .unwrap_or_default()
            .to_string();
        list.lines()
            .filter_map(|l| l.split_whitespace().next())
            .filter(|name| *name != "help")
            .map(|name| {
                let mut v: Vec<String> = prefix.iter().map(|s| s.to_string()).collect();
                v.push(name.to_string());
                v
            })
            .collect::<Vec<_>>()
    };
    for cmd in parse(&[]) {
        if cmd == ["refdb"] {
            out.extend(parse(&["refdb"]));
        } else {
            out.push(cmd);
        }
    }
    assert!(out.len() >= 14, "{out:?}");
    out
}

fn words(cmd: &[String]) -> Vec<&str> {
    cmd.iter().map(String::as_str).collect()
}

#[test]
fn json_is_a_switch_on_every_command() {
    let mut seen = 0;
    for cmd in commands() {
        for f in flags(&words(&cmd)) {
            if f.long == "json" {
                seen += 1;
                assert!(
                    !f.takes_value,
                    "eenf {}: --json takes a value",
                    cmd.join(" ")
                );
            }
        }
    }
    assert!(seen >= 9, "--json on {seen} commands");
}

/// The positional arguments of a command's usage line, as dummy paths that do not exist.
fn dummy_positionals(cmd: &[&str]) -> Vec<String> {
    let text = help(cmd);
    let usage = text.lines().find(|l| l.starts_with("Usage:")).unwrap();
    usage
        .split_whitespace()
        .filter(|w| w.starts_with('<'))
        .map(|_| "/nonexistent/eenf-flag-check".to_string())
        .collect()
}

#[test]
fn every_nominal_takes_auto() {
    let mut seen = 0;
    for cmd in commands() {
        let cmd = words(&cmd);
        if !flags(&cmd).iter().any(|f| f.long == "nominal") {
            continue;
        }
        seen += 1;
        let pos = dummy_positionals(&cmd);
        assert!(!pos.is_empty(), "eenf {cmd:?} would run for real");
        let run = |value: &str| {
            let mut args = cmd.clone();
            args.extend(["--nominal", value]);
            args.extend(pos.iter().map(String::as_str));
            cli::fails(&args, Path::new("."))
        };
        // the control: a value no command takes is refused by the flag itself
        assert!(
            run("55.5x").contains("'--nominal"),
            "eenf {cmd:?}: --nominal 55.5x not refused"
        );
        let err = run("auto");
        assert!(!err.contains("'--nominal"), "eenf {cmd:?}: {err}");
        let err = run("60");
        assert!(!err.contains("'--nominal"), "eenf {cmd:?}: {err}");
    }
    assert!(seen >= 7, "--nominal on {seen} commands");
}

#[test]
fn a_csvs_value_step_is_index_step_everywhere() {
    let mut seen = 0;
    for cmd in commands() {
        for f in flags(&words(&cmd)) {
            if f.help.contains("index,value") && f.help.contains("Seconds between") {
                seen += 1;
                assert_eq!(f.long, "index-step", "eenf {}: {f:?}", cmd.join(" "));
            }
        }
    }
    assert!(
        seen >= 4,
        "the step of an index,value CSV asked by {seen} commands"
    );
}

/// The README's commands: its section headings and the `eenf …` lines of its code blocks,
/// each with the flags it uses.
fn readme_commands() -> Vec<(String, Vec<String>)> {
    let readme = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md"))
        .expect("README.md");
    let mut lines: Vec<String> = Vec::new();
    let mut in_code = false;
    let mut joined = String::new();
    for line in readme.lines() {
        if line.starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if let Some(h) = line.strip_prefix("### `") {
            lines.push(h.split('`').next().unwrap_or("").to_string());
            continue;
        }
        if !in_code {
            continue;
        }
        joined.push_str(line.trim_end_matches('\\'));
        if line.ends_with('\\') {
            joined.push(' ');
            continue;
        }
        // `a && b`, `a | b`, `a; b`: each part on its own
        for part in joined
            .split("&&")
            .flat_map(|p| p.split('|'))
            .flat_map(|p| p.split(';'))
        {
            lines.push(part.trim().to_string());
        }
        joined.clear();
    }
    let mut out = Vec::new();
    for l in lines {
        let w: Vec<&str> = l.split_whitespace().collect();
        let start = match w.iter().position(|x| *x == "eenf") {
            Some(i) if i == 0 || w[..i].iter().all(|x| *x == "$" || x.contains('=')) => i + 1,
            _ => match w.windows(2).position(|p| p == ["--release", "--"]) {
                Some(i) if w[0] == "cargo" && w.get(1) == Some(&"run") => i + 2,
                _ => continue,
            },
        };
        // the global `-q` before the command
        let start = start + w[start..].iter().take_while(|x| **x == "-q").count();
        let Some(first) = w.get(start) else { continue };
        let mut cmd = vec![if *first == "audio" {
            "reference"
        } else {
            first
        }
        .to_string()];
        if cmd[0] == "refdb" {
            if let Some(sub) = w.get(start + 1) {
                cmd.push(sub.to_string());
            }
        }
        let used: Vec<String> = w[start..]
            .iter()
            .map(|x| {
                x.trim_start_matches(['[', '('])
                    .trim_end_matches([']', ',', '`', ')'])
            })
            .filter(|x| x.starts_with('-') && x.len() > 1)
            .filter(|x| !x.chars().nth(1).is_some_and(|c| c.is_ascii_digit()))
            .map(|x| x.split('=').next().unwrap_or(x).to_string())
            .collect();
        out.push((cmd.join(" "), used));
    }
    out
}

#[test]
fn every_flag_the_readme_shows_exists() {
    let known: BTreeMap<String, Vec<Flag>> = commands()
        .into_iter()
        .map(|c| (c.join(" "), flags(&words(&c))))
        .collect();
    let mut checked = 0;
    let mut missing = Vec::new();
    for (cmd, used) in readme_commands() {
        let Some(options) = known.get(&cmd) else {
            // `eenf` alone, or a word after `eenf` in prose that is not a command
            continue;
        };
        for u in used {
            checked += 1;
            let exists = match u.strip_prefix("--") {
                Some(long) => options.iter().any(|f| f.long == long),
                None => {
                    let c = u.chars().nth(1);
                    options.iter().any(|f| f.short == c)
                }
            };
            if !exists {
                missing.push(format!("eenf {cmd} {u}"));
            }
        }
    }
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "README flags that do not exist: {missing:#?}"
    );
    assert!(checked >= 100, "only {checked} README flags checked");
}

#[test]
fn mistyped_commands_keep_the_parsers_help() {
    let d = Path::new(".");
    let err = cli::fails(&["extract", "FILE", "--ouput", "x.csv"], d);
    assert!(
        err.contains("a similar argument exists: '--output'")
            && err.contains("Usage: eenf extract"),
        "{err}"
    );
    let err = cli::fails(&["extrat"], d);
    assert!(
        err.contains("a similar subcommand exists: 'extract'"),
        "{err}"
    );
    let err = cli::fails(&["extract"], d);
    assert!(
        err.contains("not provided") && err.contains("<FILE>"),
        "{err}"
    );
    // an output named as a folder that does not exist
    let tmp = tempfile::tempdir().unwrap();
    let err = cli::fails(
        &["simulate", "--duration", "1", "-o", "nowhere/"],
        tmp.path(),
    );
    assert!(err.contains("names a folder (it ends in /)"), "{err}");
}
