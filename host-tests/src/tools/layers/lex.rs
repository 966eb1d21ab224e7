//! The reader's lexical part: comments and literals blanked, `use` trees
//! expanded, inline paths and the names a file defines, found by scanning
//! the text (what such a reader misses: the module above).

use std::collections::BTreeSet;

/// `text` with comments, string and char literals replaced by spaces
/// (lengths kept), so that paths in them are not read as code.
pub(super) fn blank(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let mut i = 0;
    let clear = |out: &mut Vec<u8>, from: usize, to: usize| {
        for c in out.iter_mut().take(to.min(b.len())).skip(from) {
            if *c != b'\n' {
                *c = b' ';
            }
        }
    };
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            let end = b[i..].iter().position(|&c| c == b'\n').map_or(b.len(), |p| i + p);
            clear(&mut out, i, end);
            i = end;
        } else if b[i..].starts_with(b"/*") {
            let end = text[i + 2..].find("*/").map_or(b.len(), |p| i + 2 + p + 2);
            clear(&mut out, i, end);
            i = end;
        } else if b[i] == b'r' && (b.get(i + 1) == Some(&b'"') || b.get(i + 1) == Some(&b'#')) && (i == 0 || !b[i - 1].is_ascii_alphanumeric()) {
            let hashes = b[i + 1..].iter().take_while(|&&c| c == b'#').count();
            if b.get(i + 1 + hashes) != Some(&b'"') {
                i += 1;
                continue;
            }
            let close = format!("\"{}", "#".repeat(hashes));
            let start = i + 2 + hashes;
            let end = text[start..].find(&close).map_or(b.len(), |p| start + p + close.len());
            clear(&mut out, i, end);
            i = end;
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            clear(&mut out, i, j + 1);
            i = j + 1;
        } else if b[i] == b'\'' {
            // a char literal ('x', '\n', '\u{..}'), not a lifetime
            let end = if b.get(i + 1) == Some(&b'\\') {
                b[i + 2..].iter().position(|&c| c == b'\'').map(|p| i + 2 + p + 1)
            } else {
                let ch = text[i + 1..].chars().next().map_or(1, char::len_utf8);
                (b.get(i + 1 + ch) == Some(&b'\'')).then_some(i + 2 + ch)
            };
            match end {
                Some(e) => {
                    clear(&mut out, i, e);
                    i = e;
                }
                None => i += 1,
            }
        } else {
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

pub(super) fn ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Expands a `use` tree (the text between `use` and `;`) into
/// (path, name bound) pairs; `*` binds `*`.
pub(super) fn expand_use(tree: &str) -> Vec<(Vec<String>, String)> {
    fn go(s: &str, prefix: &[String], out: &mut Vec<(Vec<String>, String)>) {
        let s = s.trim();
        if s.is_empty() {
            return;
        }
        if let Some(open) = s.find('{') {
            let head: Vec<String> = s[..open].split("::").map(str::trim).filter(|x| !x.is_empty()).map(String::from).collect();
            let inner = &s[open + 1..s.rfind('}').unwrap_or(s.len())];
            let mut p = prefix.to_vec();
            p.extend(head);
            let (mut depth, mut start) = (0, 0);
            for (k, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        go(&inner[start..k], &p, out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            go(&inner[start..], &p, out);
            return;
        }
        let (path, alias) = match s.split_once(" as ") {
            Some((p, a)) => (p.trim(), Some(a.trim().to_string())),
            None => (s, None),
        };
        let mut p = prefix.to_vec();
        p.extend(path.split("::").map(str::trim).filter(|x| !x.is_empty()).map(String::from));
        if p.last().map(String::as_str) == Some("self") {
            p.pop();
        }
        let name = alias.or_else(|| p.last().cloned()).unwrap_or_default();
        out.push((p, name));
    }
    let mut out = Vec::new();
    go(tree, &[], &mut out);
    out
}

/// Every `use` statement of `code`: (is `pub`, its tree's text, offset).
pub(super) fn use_statements(code: &str) -> Vec<(bool, String, usize)> {
    let mut out = Vec::new();
    let mut rest = code;
    let mut offset = 0;
    while let Some(p) = rest.find("use ") {
        let at = offset + p;
        let before = code[..at].trim_end();
        let starts = at == 0 || !code[..at].ends_with(ident_char);
        let stmt_start = before.is_empty() || before.ends_with([';', '{', '}', ']']) || before.ends_with("pub") || before.ends_with(')');
        if starts && stmt_start {
            if let Some(end) = code[at..].find(';') {
                let public = before.ends_with("pub") || before.ends_with(')') && before.contains("pub(");
                out.push((public, code[at + 4..at + end].to_string(), at));
            }
        }
        offset = at + 4;
        rest = &code[offset..];
    }
    out
}

/// Every path that starts with `crate::`, `super::` or `self::` outside
/// `use` statements, with its offset.
pub(super) fn inline_paths(code: &str) -> Vec<(Vec<String>, usize)> {
    let mut out = Vec::new();
    for kw in ["crate::", "super::", "self::"] {
        let mut from = 0;
        while let Some(p) = code[from..].find(kw) {
            let at = from + p;
            from = at + kw.len();
            if at > 0 && code[..at].ends_with(|c: char| ident_char(c) || c == ':') {
                continue;
            }
            let tail: String = code[at..].chars().take_while(|&c| ident_char(c) || c == ':').collect();
            out.push((tail.split("::").filter(|s| !s.is_empty()).map(String::from).collect(), at));
        }
    }
    out
}

/// For each byte of `code`, how many inline `mod x { … }` blocks enclose it.
pub(super) fn inline_depth(code: &str) -> Vec<u32> {
    let mut depth = vec![0u32; code.len()];
    let b = code.as_bytes();
    let mut from = 0;
    while let Some(p) = code[from..].find("mod ") {
        let at = from + p;
        from = at + 4;
        if at > 0 && ident_char(char::from(b[at - 1])) {
            continue;
        }
        let name_end = at + 4 + code[at + 4..].find(|c: char| !ident_char(c)).unwrap_or(0);
        let rest = code[name_end..].trim_start();
        if !rest.starts_with('{') {
            continue;
        }
        let open = code.len() - rest.len();
        let mut level = 0i32;
        for (k, c) in code[open..].char_indices() {
            match c {
                '{' => level += 1,
                '}' => {
                    level -= 1;
                    if level == 0 {
                        depth.iter_mut().take(open + k).skip(open).for_each(|d| *d += 1);
                        break;
                    }
                }
                _ => {}
            }
        }
    }
    depth
}

/// Names a file defines at its top level or in its modules (`fn`, `struct`,
/// `enum`, `trait`, `type`, `const`, `static`, `mod`, `union`, `macro_rules!`).
pub(super) fn defined_names(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let words: Vec<&str> = code.split(|c: char| !ident_char(c) && c != '!').filter(|w| !w.is_empty()).collect();
    for w in words.windows(2) {
        if matches!(w[0], "fn" | "struct" | "enum" | "trait" | "type" | "const" | "static" | "mod" | "union" | "macro_rules!") {
            out.insert(w[1].to_string());
        }
    }
    out
}
