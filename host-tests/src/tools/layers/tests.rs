//! Tests of the module-graph reader on small sources.

use super::*;

fn mp(s: &str) -> ModPath {
    s.split("::").map(String::from).collect()
}

#[test]
fn use_trees_expand_with_groups_aliases_and_self() {
    let got = expand_use("crate::a::{b, c::{d as e, self}, f::*}");
    let want = [("crate::a::b", "b"), ("crate::a::c::d", "e"), ("crate::a::c", "c"), ("crate::a::f::*", "*")];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for ((p, n), (wp, wn)) in got.iter().zip(want) {
        assert_eq!((p.join("::"), n.as_str()), (wp.to_string(), wn));
    }
}

#[test]
fn comments_and_strings_are_not_code() {
    let b = blank("let s = \"use crate::x;\"; // crate::y\nlet c = '\\''; /* crate::z */ crate::w::f();");
    assert_eq!(inline_paths(&b).into_iter().map(|(p, _)| p).collect::<Vec<_>>(), vec![mp("crate::w::f")]);
}

/// The host crate's layers and the firmware crate's cycles, as read
/// from the sources. Listed below are the violations that stand today;
/// the test fails on a new one and on a listed one that has gone (so
/// the list only shrinks).
#[test]
fn imports_run_one_way_except_the_listed() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let host = Graph::read(&root.join("src")).expect("reads host-tests/src");
    let fw = Graph::read(&root.join("../src")).expect("reads src");
    assert!(host.edges.len() > 80 && fw.edges.len() > 40, "{} / {} modules", host.edges.len(), fw.edges.len());
    let mut found = Vec::new();
    for (name, g) in [("host", &host), ("firmware", &fw)] {
        for c in g.cycles() {
            found.push(format!("{name} cycle: {}", c.iter().map(show).collect::<Vec<_>>().join(" ↔ ")));
        }
    }
    for (a, b) in host.upward(host_rank) {
        found.push(format!("host upward: {} → {}", show(&a), show(&b)));
    }
    found.sort();
    let listed: Vec<String> = KNOWN.iter().map(|s| (*s).to_string()).collect();
    let new: Vec<&String> = found.iter().filter(|f| !listed.contains(f)).collect();
    let gone: Vec<&String> = listed.iter().filter(|l| !found.contains(l)).collect();
    assert!(new.is_empty() && gone.is_empty(), "new violations:\n{}\nlisted but gone (remove from KNOWN):\n{}", new.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n"), gone.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n"));
}

/// The host crate's layers, bottom to top: the data layer (the
/// measured-data format, plots), the physics, the simulation, the
/// calibration and the emulator, the diagnosis, the tools and the
/// firmware harnesses, the command line.
fn host_rank(p: &ModPath) -> Option<u32> {
    let s: Vec<&str> = p.iter().map(String::as_str).collect();
    Some(match s.as_slice() {
        ["data", ..] => 0,
        ["physics", ..] => 1,
        ["simulation", ..] | ["tools", "reduce"] => 2,
        [_, "cli"] | ["tools", "gendoc" | "rigdoc" | "layers", ..] => 7,
        ["calibration", ..] | ["emulator", ..] | ["tools", "params_block"] => 3,
        ["diagnosis", ..] => 4,
        ["tools", ..] => 5,
        ["pil", ..] | ["faults", ..] => 6,
        _ => return None,
    })
}

/// Violations that stand (see the test above): none.
const KNOWN: &[&str] = &[];
