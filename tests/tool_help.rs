//! Every argument of every `gnss_ins` command says what it is in `-h` (issue 16: `BAG`,
//! `--out` and `--seed` had no help text), and `--scenario` names the built-ins when the
//! value is neither one of them nor a file.

use std::process::{Command, Output};

fn gnss_ins(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gnss_ins"))
        .args(args)
        .output()
        .unwrap()
}

fn stdout_of(args: &[&str]) -> String {
    let out = gnss_ins(args);
    assert!(out.status.success(), "gnss_ins {args:?} failed");
    String::from_utf8(out.stdout).unwrap()
}

/// The subcommands listed by `gnss_ins -h`.
fn commands() -> Vec<String> {
    let help = stdout_of(&["-h"]);
    let mut lines = help.lines().skip_while(|l| *l != "Commands:").skip(1);
    let mut names = Vec::new();
    for line in lines.by_ref() {
        let Some(name) = line
            .strip_prefix("  ")
            .and_then(|l| l.split_whitespace().next())
        else {
            break;
        };
        if name != "help" {
            names.push(name.to_owned());
        }
    }
    names
}

/// The arguments of one `-h` page that have no text of their own (a line of defaults or
/// possible values alone does not count).
fn arguments_without_help(help: &str) -> Vec<String> {
    let lines: Vec<&str> = help.lines().collect();
    let mut missing = Vec::new();
    let mut in_section = false;
    for (i, line) in lines.iter().enumerate() {
        if line.ends_with(':') && !line.starts_with(' ') {
            in_section = *line == "Arguments:" || *line == "Options:";
            continue;
        }
        // Entries are indented by 2 to 6 spaces, their texts on the next lines by 10.
        let entry = line.trim_start();
        let indent = line.len() - entry.len();
        let is_entry =
            (2..=6).contains(&indent) && (entry.starts_with('-') || entry.starts_with('<'));
        if !in_section || !is_entry {
            continue;
        }
        let same_line = entry.split_once("  ").map(|(_, text)| text.trim());
        let text = match same_line {
            Some(text) if !text.is_empty() => text,
            _ => lines
                .get(i + 1)
                .filter(|next| next.starts_with("          "))
                .map_or("", |next| next.trim()),
        };
        if text.is_empty() || text.starts_with('[') {
            missing.push(entry.trim().to_owned());
        }
    }
    missing
}

#[test]
fn every_argument_of_every_command_has_help() {
    let commands = commands();
    assert!(commands.len() >= 8, "commands found: {commands:?}");
    let mut missing = Vec::new();
    for command in &commands {
        let help = stdout_of(&[command, "-h"]);
        for argument in arguments_without_help(&help) {
            missing.push(format!("gnss_ins {command} {argument}"));
        }
    }
    assert!(missing.is_empty(), "no help text:\n{}", missing.join("\n"));
}

#[test]
fn the_help_check_sees_a_missing_text() {
    let page = "Options:\n      --out <OUT>  \n      --seed <SEED>  [default: 1]\n      \
                --ok <OK>  Output\n  -h, --help\n          Print help\n";
    assert_eq!(
        arguments_without_help(page),
        ["--out <OUT>", "--seed <SEED>  [default: 1]"]
    );
}

#[test]
fn an_unknown_scenario_names_the_built_ins() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.mcap");
    let result = gnss_ins(&[
        "simulate",
        "--scenario",
        "nope",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!result.status.success());
    let stderr = String::from_utf8_lossy(&result.stderr);
    for name in ["default", "open_sky", "static"] {
        assert!(stderr.contains(name), "{stderr}");
    }
}
