//! The command line's guide (docs/cli.md), the completion scripts and the manual pages against the
//! binary's own `--help`: the guide has a section for every command and names exactly the options
//! that command's `--help` lists, so that neither can drift from the other.

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::process::Command;

fn fairmesh(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_fairmesh"))
        .args(args)
        .output()
        .expect("fairmesh runs");
    assert!(
        output.status.success(),
        "fairmesh {args:?} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).expect("utf-8 output")
}

/// The commands `fairmesh --help` lists (without `help`).
fn commands() -> Vec<String> {
    let help = fairmesh(&["--help"]);
    let listed = help
        .split("Commands:")
        .nth(1)
        .expect("--help lists the commands")
        .split("\n\n")
        .next()
        .unwrap();
    listed
        .lines()
        .filter_map(|line| line.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_owned)
        .collect()
}

/// The long options `fairmesh COMMAND --help` lists, without `--help` and `--version`.
fn options_in_help(command: &str) -> BTreeSet<String> {
    fairmesh(&[command, "--help"])
        .lines()
        .filter_map(|line| {
            let line = line.trim_start();
            // "-o, --output <OUTPUT>" or "--json".
            let line = match line.strip_prefix('-') {
                Some(rest) if !rest.starts_with('-') => rest.get(3..)?,
                _ => line,
            };
            let name = line.strip_prefix("--")?;
            let name: String = name
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect();
            (!name.is_empty()).then_some(name)
        })
        .filter(|name| name != "help" && name != "version")
        .collect()
}

/// Every `--option` named in a piece of Markdown.
fn options_named(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let bytes = text.as_bytes();
    let mut i = 0;
    while let Some(at) = text[i..].find("--") {
        let start = i + at + 2;
        let before_ok = i + at == 0 || !bytes[i + at - 1].is_ascii_alphanumeric();
        let name: String = text[start..]
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
            .collect();
        if before_ok && name.starts_with(|c: char| c.is_ascii_lowercase()) {
            found.insert(name.trim_end_matches('-').to_owned());
        }
        i = start;
    }
    found
}

/// The guide's sections headed "## `fairmesh COMMAND`", by command.
fn guide_sections() -> BTreeMap<String, String> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/cli.md");
    let guide = std::fs::read_to_string(&path).expect("docs/cli.md exists");
    let mut sections = BTreeMap::new();
    let mut current: Option<(String, String)> = None;
    for line in guide.lines() {
        if line.starts_with("## ") || line.starts_with("# ") {
            if let Some((name, text)) = current.take() {
                sections.insert(name, text);
            }
            if let Some(rest) = line.strip_prefix("## `fairmesh ") {
                let name = rest.trim_end_matches('`').to_owned();
                current = Some((name, String::new()));
            }
        } else if let Some((_, text)) = current.as_mut() {
            text.push_str(line);
            text.push('\n');
        }
    }
    if let Some((name, text)) = current {
        sections.insert(name, text);
    }
    sections
}

#[test]
fn the_guide_has_a_section_for_every_command_and_no_other() {
    let commands: BTreeSet<String> = commands().into_iter().collect();
    assert!(
        commands.contains("fair") && commands.contains("multires"),
        "{commands:?}"
    );
    let sections: BTreeSet<String> = guide_sections().into_keys().collect();
    assert_eq!(
        sections, commands,
        "docs/cli.md's \"## `fairmesh COMMAND`\" sections against `fairmesh --help`'s commands"
    );
}

#[test]
fn the_guide_names_exactly_the_options_of_each_command() {
    let sections = guide_sections();
    let mut wrong = Vec::new();
    for command in commands() {
        let in_help = options_in_help(&command);
        let in_guide = sections
            .get(&command)
            .map(|text| options_named(text))
            .unwrap_or_default();
        let missing: Vec<_> = in_help.difference(&in_guide).collect();
        let unknown: Vec<_> = in_guide.difference(&in_help).collect();
        if !missing.is_empty() || !unknown.is_empty() {
            wrong.push(format!(
                "{command}: in --help, not in the guide: {missing:?}; in the guide, not in --help: {unknown:?}"
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "docs/cli.md and --help disagree:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_option_reader_finds_what_help_lists() {
    // The comparison above is only as good as the reading of `--help`.
    let fair = options_in_help("fair");
    for name in [
        "output",
        "rounds",
        "mask-falloff",
        "no-volume-correction",
        "json",
    ] {
        assert!(
            fair.contains(name),
            "{name} not read from fair --help: {fair:?}"
        );
    }
    assert!(!fair.contains("help"));
    let named = options_named("`-o`, `--output OUT`; --mask-falloff 3, not a--b nor -- nor --X");
    assert_eq!(
        named,
        ["mask-falloff", "output"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    );
}

#[test]
fn the_bash_completion_script_is_valid_bash_and_completes_the_commands() {
    let script = fairmesh(&["completions", "bash"]);
    for command in commands() {
        assert!(
            script.contains(&command),
            "no {command} in the bash completions"
        );
    }
    assert!(script.contains("--mask-falloff"));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fairmesh.bash");
    std::fs::write(&path, &script).unwrap();
    let check = Command::new("bash")
        .arg("-n")
        .arg(&path)
        .output()
        .expect("bash runs");
    assert!(
        check.status.success(),
        "bash -n rejects the completion script: {}",
        String::from_utf8_lossy(&check.stderr)
    );
    for shell in ["zsh", "fish", "powershell", "elvish"] {
        assert!(
            fairmesh(&["completions", shell]).contains("multires"),
            "{shell}"
        );
    }
}

#[test]
fn man_writes_a_page_per_command_that_names_its_options() {
    let dir = tempfile::tempdir().unwrap();
    let printed = fairmesh(&["man", dir.path().to_str().unwrap()]);
    let mut expected: Vec<String> = commands()
        .iter()
        .map(|command| format!("fairmesh-{command}.1"))
        .collect();
    expected.push("fairmesh.1".to_owned());
    for name in &expected {
        let path = dir.path().join(name);
        assert!(
            printed.contains(&path.display().to_string()),
            "{name} not printed"
        );
        let page = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            page.starts_with(".ie") || page.contains(".TH"),
            "{name} is no man page"
        );
    }
    let fair = std::fs::read_to_string(dir.path().join("fairmesh-fair.1")).unwrap();
    // roff escapes the dashes of options: \-\-mask\-falloff.
    assert!(
        fair.contains(r"\-\-mask\-falloff"),
        "fairmesh-fair.1 lacks --mask-falloff"
    );
    let files = std::fs::read_dir(dir.path()).unwrap().count();
    assert_eq!(
        files,
        expected.len(),
        "no stray or temporary file is left behind"
    );
    // Rendered by man itself where it is installed.
    if let Ok(rendered) = Command::new("man")
        .arg("-l")
        .arg(dir.path().join("fairmesh-fair.1"))
        .env("MANWIDTH", "100")
        .env("MAN_KEEP_FORMATTING", "0")
        .output()
    {
        let text = String::from_utf8_lossy(&rendered.stdout);
        assert!(rendered.status.success(), "man -l failed");
        assert!(text.contains("fairmesh-fair"), "man -l rendered: {text}");
    } else {
        eprintln!("man is not installed: the pages were checked as text only");
    }
}
