//! The module graph of a crate, read from its sources, so that a test can
//! keep imports running one way: every `use` tree and every `crate::` /
//! `super::` / `self::` path is resolved, through `pub use` re-exports, to
//! the module where the item is defined; the edges between modules then give
//! the cycles (strongly connected components) and the arrows that point up
//! a declared layer order.
//!
//! A reader, not a compiler: macros are not expanded and method calls carry
//! no path, so an edge is only ever missed, never invented (a missed edge
//! can hide a cycle; the test says which were found). Comments and string
//! literals are blanked before reading.

mod lex;

use lex::{blank, defined_names, expand_use, inline_depth, inline_paths, use_statements};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module path inside its crate (`[]` = the crate root).
pub type ModPath = Vec<String>;

/// The crate's modules and the edges between them.
#[derive(Debug, Default)]
pub struct Graph {
    /// Module → the modules it uses (self and descendants excluded).
    pub edges: BTreeMap<ModPath, BTreeSet<ModPath>>,
}

/// One source file: its text with comments and literals blanked, the
/// names it defines, its `pub use` re-exports and its glob re-exports.
#[derive(Debug, Default)]
struct Module {
    code: String,
    defines: BTreeSet<String>,
    reexports: BTreeMap<String, Vec<String>>,
    globs: Vec<Vec<String>>,
}

/// The module paths of every `.rs` file under `src` (a `main.rs` of a
/// `bin/` folder is that binary's root and is left out with its folder).
fn modules(src: &Path) -> std::io::Result<BTreeMap<ModPath, Module>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir)? {
            let p = e?.path();
            let rel = p.strip_prefix(src).map_err(std::io::Error::other)?;
            if rel.starts_with("bin") {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            if p.extension().and_then(|x| x.to_str()) != Some("rs") {
                continue;
            }
            let mut path: ModPath = rel.with_extension("").iter().map(|c| c.to_string_lossy().into_owned()).collect();
            if matches!(path.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                path.pop();
            }
            if rel == Path::new("main.rs") {
                continue;
            }
            let code = blank(&std::fs::read_to_string(&p)?);
            let mut m = Module { defines: defined_names(&code), ..Module::default() };
            for (public, tree, _) in use_statements(&code) {
                if !public {
                    continue;
                }
                for (target, name) in expand_use(&tree) {
                    if name == "*" {
                        m.globs.push(target[..target.len() - 1].to_vec());
                    } else {
                        m.reexports.insert(name, target);
                    }
                }
            }
            m.code = code;
            out.insert(path, m);
        }
    }
    Ok(out)
}

impl Graph {
    /// Reads the crate whose sources are under `src`.
    pub fn read(src: &Path) -> std::io::Result<Graph> {
        let mods = modules(src)?;
        let mut g = Graph::default();
        for (here, m) in &mods {
            let mut paths: Vec<(Vec<String>, usize)> =
                use_statements(&m.code).into_iter().flat_map(|(_, t, at)| expand_use(&t).into_iter().map(move |(p, _)| (p, at))).collect();
            paths.extend(inline_paths(&m.code));
            let depth = inline_depth(&m.code);
            let targets = g.edges.entry(here.clone()).or_default();
            for (mut p, at) in paths {
                // `super` inside an inline `mod x { }` first leaves that block
                let inner = depth.get(at).copied().unwrap_or(0);
                let supers = p.iter().take_while(|s| *s == "super").count();
                if inner > 0 && supers > 0 {
                    let drop = (inner as usize).min(supers);
                    p.drain(..drop);
                    p.insert(0, "self".into());
                }
                if let Some(t) = resolve(&mods, here, &p, 0) {
                    if !t.starts_with(here) {
                        targets.insert(t);
                    }
                }
            }
        }
        Ok(g)
    }

    /// The cycles: strongly connected components of more than one module
    /// (Tarjan), each sorted, in module order.
    pub fn cycles(&self) -> Vec<Vec<ModPath>> {
        let nodes: Vec<&ModPath> = self.edges.keys().collect();
        let index_of: BTreeMap<&ModPath, usize> = nodes.iter().enumerate().map(|(i, n)| (*n, i)).collect();
        let succ: Vec<Vec<usize>> = nodes.iter().map(|n| self.edges[*n].iter().filter_map(|t| index_of.get(t).copied()).collect()).collect();
        let n = nodes.len();
        let (mut index, mut low, mut on) = (vec![usize::MAX; n], vec![0; n], vec![false; n]);
        let (mut stack, mut out, mut next) = (Vec::new(), Vec::new(), 0);
        // iterative Tarjan: (node, next successor to visit)
        for root in 0..n {
            if index[root] != usize::MAX {
                continue;
            }
            let mut call = vec![(root, 0usize)];
            while let Some(&mut (v, ref mut k)) = call.last_mut() {
                if *k == 0 && index[v] == usize::MAX {
                    index[v] = next;
                    low[v] = next;
                    next += 1;
                    stack.push(v);
                    on[v] = true;
                }
                if let Some(&w) = succ[v].get(*k) {
                    *k += 1;
                    if index[w] == usize::MAX {
                        call.push((w, 0));
                    } else if on[w] {
                        low[v] = low[v].min(index[w]);
                    }
                    continue;
                }
                call.pop();
                if let Some(&(u, _)) = call.last() {
                    low[u] = low[u].min(low[v]);
                }
                if low[v] == index[v] {
                    let mut comp = Vec::new();
                    while let Some(w) = stack.pop() {
                        on[w] = false;
                        comp.push(nodes[w].clone());
                        if w == v {
                            break;
                        }
                    }
                    if comp.len() > 1 {
                        comp.sort();
                        out.push(comp);
                    }
                }
            }
        }
        out.sort();
        out
    }

    /// The edges from a module to one of a higher layer: `rank` gives a
    /// module's layer (modules it returns `None` for are not ranked).
    pub fn upward(&self, rank: impl Fn(&ModPath) -> Option<u32>) -> Vec<(ModPath, ModPath)> {
        let mut out = Vec::new();
        for (from, tos) in &self.edges {
            for to in tos {
                if let (Some(a), Some(b)) = (rank(from), rank(to)) {
                    if b > a {
                        out.push((from.clone(), to.clone()));
                    }
                }
            }
        }
        out
    }
}

/// The module where the item `path` (seen from module `here`) is defined;
/// `None` for another crate's item.
fn resolve(mods: &BTreeMap<ModPath, Module>, here: &ModPath, path: &[String], depth: u32) -> Option<ModPath> {
    if depth > 16 {
        return None;
    }
    let (mut cur, rest): (ModPath, &[String]) = match path.first().map(String::as_str) {
        Some("crate") => (Vec::new(), &path[1..]),
        Some("self") => (here.clone(), &path[1..]),
        Some("super") => {
            let mut base = here.clone();
            let mut k = 0;
            while path.get(k).map(String::as_str) == Some("super") {
                base.pop();
                k += 1;
            }
            (base, &path[k..])
        }
        Some(first) => {
            let mut child = here.clone();
            child.push(first.to_string());
            if !mods.contains_key(&child) {
                return None;
            }
            (here.clone(), path)
        }
        None => return None,
    };
    for (k, seg) in rest.iter().enumerate() {
        let mut next = cur.clone();
        next.push(seg.clone());
        if mods.contains_key(&next) {
            cur = next;
            continue;
        }
        let m = mods.get(&cur)?;
        if let Some(target) = m.reexports.get(seg) {
            let mut full = target.clone();
            full.extend(rest[k + 1..].iter().cloned());
            return resolve(mods, &cur, &full, depth + 1).or(Some(cur));
        }
        if !m.defines.contains(seg) {
            for g in &m.globs {
                let mut full = g.clone();
                full.extend(rest[k..].iter().cloned());
                if let Some(t) = resolve(mods, &cur, &full, depth + 1) {
                    if mods.get(&t).is_some_and(|tm| tm.defines.contains(seg) || tm.reexports.contains_key(seg)) {
                        return Some(t);
                    }
                }
            }
        }
        return Some(cur);
    }
    Some(cur)
}

/// A module path as `a::b` (`crate` for the root).
pub fn show(p: &ModPath) -> String {
    if p.is_empty() {
        "crate".into()
    } else {
        p.join("::")
    }
}

#[cfg(test)]
mod tests;
