//! Stable-toolchain fallback of the reader fuzz targets (`fuzz/`, nightly):
//! the measured-data reader, the mission CSV reader and the rig TOML loader
//! on every committed fuzz corpus file, on proptest mutations of those files
//! and on arbitrary bytes. Each must give a value or an error, never a panic;
//! what they accept must also pass the same checks as in the fuzz targets.

use crate::reader_checks::{check_measured, check_mission, check_rig};
use proptest::prelude::*;
use proptest::sample::Index;
use std::path::PathBuf;

/// The committed corpus of fuzz target `target`, sorted by file name.
fn corpus(target: &str) -> Vec<Vec<u8>> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus").join(target);
    let mut files: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| {
            let p = e.expect("corpus entry").path();
            let b = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p, b)
        })
        .collect();
    files.sort();
    assert!(!files.is_empty(), "empty corpus {}", dir.display());
    files.into_iter().map(|f| f.1).collect()
}


/// Fragments that matter to CSV and TOML parsers and to the value checks.
const TOKENS: &[&str] = &[
    ",", "\n", "\r\n", "\r", "\"", "#", " ", "\t", "NaN", "nan", "inf", "-inf", "-", "+", ".", "e", "e999", "1e-400",
    "-0", "0x10", "1_000", "99999999999999999999999", "\u{feff}", "é", "\0", "=", "[", "]", "{", "}", "[[", "]]", "'''",
    "\"\"\"", "time_s", "ambient_c", "speed_rpm", "position_mm", "none", "true", ":", "# rig: x\n", "[ext]\n",
];

#[derive(Clone, Debug)]
enum Edit {
    Flip(Index, u8),
    Insert(Index, Index),
    Delete(Index, usize),
    Truncate(Index),
    DupLine(Index),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        1 => (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Edit::Flip(i, b)),
        3 => (any::<Index>(), any::<Index>()).prop_map(|(i, t)| Edit::Insert(i, t)),
        1 => (any::<Index>(), 1usize..40).prop_map(|(i, n)| Edit::Delete(i, n)),
        1 => any::<Index>().prop_map(Edit::Truncate),
        1 => any::<Index>().prop_map(Edit::DupLine),
    ]
}

fn apply(mut b: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        let n = b.len().max(1);
        match e {
            Edit::Flip(i, x) => {
                if !b.is_empty() {
                    let k = i.index(n);
                    b[k] ^= x;
                }
            }
            Edit::Insert(i, t) => {
                let k = i.index(n + 1).min(b.len());
                let tok = TOKENS[t.index(TOKENS.len())].as_bytes();
                b.splice(k..k, tok.iter().copied());
            }
            Edit::Delete(i, len) => {
                let k = i.index(n).min(b.len());
                let end = (k + len).min(b.len());
                b.drain(k..end);
            }
            Edit::Truncate(i) => b.truncate(i.index(n + 1)),
            Edit::DupLine(i) => {
                let lines: Vec<&[u8]> = b.split_inclusive(|&c| c == b'\n').collect();
                if !lines.is_empty() {
                    let k = i.index(lines.len());
                    let mut out = Vec::with_capacity(b.len() + lines[k].len());
                    for (j, l) in lines.iter().enumerate() {
                        out.extend_from_slice(l);
                        if j == k {
                            out.extend_from_slice(l);
                        }
                    }
                    b = out;
                }
            }
        }
    }
    b
}

fn mutated(target: &'static str) -> impl Strategy<Value = Vec<u8>> {
    let seeds = corpus(target);
    (any::<Index>(), proptest::collection::vec(edit(), 0..8))
        .prop_map(move |(i, edits)| apply(seeds[i.index(seeds.len())].clone(), &edits))
}

#[test]
fn readers_accept_or_reject_every_corpus_file() {
    for b in corpus("measured_csv") {
        check_measured(&b);
    }
    for b in corpus("mission_csv") {
        check_mission(&b);
    }
    for b in corpus("rig_toml") {
        check_rig(&b);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn measured_reader_never_panics_on_mutated_files(b in mutated("measured_csv")) {
        check_measured(&b);
    }

    #[test]
    fn mission_reader_never_panics_on_mutated_files(b in mutated("mission_csv")) {
        check_mission(&b);
    }

    #[test]
    fn rig_loader_never_panics_on_mutated_files(b in mutated("rig_toml")) {
        check_rig(&b);
    }

    #[test]
    fn readers_never_panic_on_arbitrary_bytes(b in proptest::collection::vec(any::<u8>(), 0..400)) {
        check_measured(&b);
        check_mission(&b);
        check_rig(&b);
    }
}
