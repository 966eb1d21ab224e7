//! A newcomer's path: the README's first two commands (the main job, the
//! tests) are the ones `.ci/run` executes, so that what CI proves is what a
//! new user types first.

use std::path::Path;

/// The command lines of the README's ```sh blocks, in order, without
/// their trailing comments.
fn readme_commands() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = std::fs::read_to_string(root.join("README.md")).expect("README.md");
    let mut out = Vec::new();
    let mut inside = false;
    for line in text.lines() {
        if line.starts_with("```") {
            inside = line == "```sh";
            continue;
        }
        let cmd = line.split(" #").next().unwrap_or("").trim();
        if inside && !cmd.is_empty() {
            out.push(cmd.to_string());
        }
    }
    out
}

#[test]
fn the_readmes_first_two_commands_are_what_ci_runs() {
    let cmds = readme_commands();
    assert!(cmds.len() >= 2, "{cmds:?}");
    let ci = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../.ci/run")).expect(".ci/run");
    // The main job: `eha-sim` is `cargo run --profile fast -p eha-sim --`;
    // .ci/run calls the binary the test build made (same profile, same
    // code) with the same arguments.
    let main_job = &cmds[0];
    let args = main_job.strip_prefix("cargo run --profile fast -p eha-sim -- ").unwrap_or_else(|| panic!("the first command is not eha-sim: {main_job}"));
    assert!(ci.contains(&format!("\"$EHA_SIM\" {args}")), ".ci/run does not run the main job `{main_job}`");
    // The tests: the fast tier, verbatim.
    assert_eq!(cmds[1], "cargo test --profile fast --workspace", "the second command");
    assert!(ci.lines().any(|l| !l.trim_start().starts_with('#') && l.contains(&cmds[1])), ".ci/run does not run `{}`", cmds[1]);
}
