//! Imports go one way: no file of `src/` imports another that imports it back, directly or around
//! a circle. Read from the sources: every `use` tree and every `crate::` / `super::` / `self::` /
//! `strata::` path outside comments, string literals and `#[cfg(test)]` modules, resolved to the file
//! of the longest module prefix. A parent's `mod child;` and relative `use child::X` are not edges
//! (a folder's `mod.rs` may re-export its children).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`, relative to `root`, with `/` separators.
fn rust_files(root: &Path, dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(root, &p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p.strip_prefix(root).unwrap().to_string_lossy().replace('\\', "/"));
        }
    }
}

/// The module path of a file: `a/b.rs` and `a/b/mod.rs` are `[a, b]`; `lib.rs` and `main.rs` `[]`.
fn module_of(file: &str) -> Vec<String> {
    let mut parts: Vec<String> = file.trim_end_matches(".rs").split('/').map(str::to_string).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
        parts.pop();
    }
    parts
}

/// The code of a file without comments, string and char literals, and `#[cfg(test)]` modules
/// (an inline one ends the file: tests come last; an out-of-line one is just skipped).
fn code_of(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let mut kept = String::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim() == "#[cfg(test)]" {
            let mut j = i + 1;
            while j < lines.len() && lines[j].trim_start().starts_with("#[") {
                j += 1;
            }
            let item = lines.get(j).map_or("", |l| l.trim());
            let item = item.strip_prefix("pub(crate) ").or_else(|| item.strip_prefix("pub ")).unwrap_or(item);
            if item.starts_with("mod ") {
                if item.ends_with(';') {
                    i = j + 1;
                    continue;
                }
                break;
            }
        }
        kept.push_str(lines[i]);
        kept.push('\n');
        i += 1;
    }
    // Comments and literals out, character by character.
    let (b, mut out, mut k) = (kept.as_bytes(), String::new(), 0);
    while k < b.len() {
        match b[k] {
            b'/' if b.get(k + 1) == Some(&b'/') => {
                while k < b.len() && b[k] != b'\n' {
                    k += 1;
                }
            }
            b'/' if b.get(k + 1) == Some(&b'*') => {
                k += 2;
                while k + 1 < b.len() && !(b[k] == b'*' && b[k + 1] == b'/') {
                    k += 1;
                }
                k += 2;
            }
            b'"' => {
                // A raw string's `r#"` leaves `r#` behind (harmless); its body may hold `"`.
                let hashes = b[..k].iter().rev().take_while(|&&c| c == b'#').count();
                let raw = k > hashes && b[k - hashes - 1] == b'r';
                k += 1;
                while k < b.len() {
                    if raw {
                        if b[k] == b'"' && b[k + 1..].iter().take(hashes).filter(|&&c| c == b'#').count() == hashes {
                            k += 1 + hashes;
                            break;
                        }
                    } else if b[k] == b'\\' {
                        k += 1;
                    } else if b[k] == b'"' {
                        k += 1;
                        break;
                    }
                    k += 1;
                }
                out.push_str("\"\"");
            }
            // A char literal (not a lifetime): 'x', '\n', '\u{..}'.
            b'\'' if b.get(k + 2) == Some(&b'\'') || b.get(k + 1) == Some(&b'\\') => {
                k += 1;
                while k < b.len() && b[k] != b'\'' {
                    k += if b[k] == b'\\' { 2 } else { 1 };
                }
                k += 1;
                out.push_str("' '");
            }
            c => {
                out.push(c as char);
                k += 1;
            }
        }
    }
    out
}

/// A `use` tree expanded into its paths: `a::{b, c::{d, e as f}}` is `a::b`, `a::c::d`, `a::c::e`.
fn expand(tree: &str) -> Vec<String> {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        return vec![tree.split(" as ").next().unwrap().trim().to_string()];
    };
    let (prefix, inner) = (&tree[..open], &tree[open + 1..tree.rfind('}').unwrap()]);
    let (mut parts, mut depth, mut cur) = (Vec::new(), 0, String::new());
    for ch in inner.chars() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(std::mem::take(&mut cur));
                continue;
            }
            _ => {}
        }
        cur.push(ch);
    }
    parts.push(cur);
    parts.iter().filter(|p| !p.trim().is_empty()).flat_map(|p| expand(&format!("{prefix}{}", p.trim()))).collect()
}

/// The paths a file names: its `use` trees expanded, and every path starting with `crate`,
/// `super`, `self` or `strata` (the library's own name, used by `cli.rs`).
fn paths_in(code: &str) -> Vec<String> {
    let mut paths = Vec::new();
    let words: Vec<(usize, &str)> = code
        .char_indices()
        .filter(|&(i, c)| c.is_alphabetic() && (i == 0 || !is_ident(code.as_bytes()[i - 1] as char)))
        .map(|(i, _)| (i, &code[i..]))
        .collect();
    for (_, rest) in words {
        if let Some(tree) = rest.strip_prefix("use ") {
            if let Some(end) = tree.find(';') {
                paths.extend(expand(&tree[..end].split_whitespace().collect::<Vec<_>>().join(" ")));
            }
        }
        for root in ["crate::", "super::", "self::", "strata::"] {
            if rest.starts_with(root) {
                let end = rest.find(|c: char| !(is_ident(c) || c == ':')).unwrap_or(rest.len());
                // `super::{a, b}`: the prefix of a use tree, whose paths `expand` gives.
                if !rest[end..].starts_with('{') {
                    paths.push(rest[..end].trim_end_matches(':').to_string());
                }
            }
        }
    }
    paths
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The files each file of `src/` imports.
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, src, &mut files);
    // main.rs's modules are files of the library as well (cli.rs is compiled into both).
    let modules: BTreeMap<Vec<String>, String> =
        files.iter().filter(|f| *f != "main.rs").map(|f| (module_of(f), f.clone())).collect();
    let mut g = BTreeMap::new();
    for f in &files {
        let text = std::fs::read_to_string(src.join(f)).unwrap();
        let me = module_of(f);
        let mut to = BTreeSet::new();
        for p in paths_in(&code_of(&text)) {
            let segs: Vec<&str> = p.split("::").map(str::trim).filter(|s| !s.is_empty()).collect();
            let abs: Vec<String> = match segs.first() {
                Some(&"crate" | &"strata") => segs[1..].iter().map(|s| s.to_string()).collect(),
                Some(&"self") => me.iter().cloned().chain(segs[1..].iter().map(|s| s.to_string())).collect(),
                Some(&"super") => {
                    let ups = segs.iter().take_while(|s| **s == "super").count();
                    let base = &me[..me.len().saturating_sub(ups)];
                    base.iter().cloned().chain(segs[ups..].iter().map(|s| s.to_string())).collect()
                }
                _ => continue,
            };
            if let Some(t) = (1..=abs.len()).rev().find_map(|k| modules.get(&abs[..k])) {
                if t != f {
                    to.insert(t.clone());
                }
            }
        }
        g.insert(f.clone(), to);
    }
    g
}

/// The strongly connected components with more than one file (Tarjan), each sorted.
fn circles(g: &BTreeMap<String, BTreeSet<String>>) -> BTreeSet<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: BTreeSet<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let n = t.index.len();
        t.index.insert(v, n);
        t.low.insert(v, n);
        t.stack.push(v);
        t.on.insert(v);
        for w in &t.g[v] {
            if !t.index.contains_key(w.as_str()) {
                visit(t, w);
                let lw = t.low[w.as_str()];
                t.low.entry(v).and_modify(|l| *l = (*l).min(lw));
            } else if t.on.contains(w.as_str()) {
                let iw = t.index[w.as_str()];
                t.low.entry(v).and_modify(|l| *l = (*l).min(iw));
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.insert(comp);
            }
        }
    }
    let mut t =
        T { g, index: BTreeMap::new(), low: BTreeMap::new(), stack: vec![], on: BTreeSet::new(), out: BTreeSet::new() };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out
}

#[test]
fn no_file_circles_in_src() {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let found = circles(&graph(&src));
    assert!(
        found.is_empty(),
        "files that import each other (around a circle): {found:?}; move the shared piece down a level"
    );
}

/// The checker itself, on a made-up tree: a circle through `super::` and a `use` tree is found,
/// comments, strings and test modules are not read, and a parent's re-export is no edge.
#[test]
fn the_circle_finder_sees_use_trees_and_ignores_comments_strings_and_tests() {
    let d = crate::common::tmpdir("layering");
    let write = |f: &str, s: &str| {
        let p = d.join(f);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, s).unwrap();
    };
    write("lib.rs", "pub mod a;\npub mod b;\n");
    write("a/mod.rs", "mod x;\nmod y;\nmod z;\npub use x::X;\n");
    write("a/x.rs", "use super::{y::{Y, W as V}};\npub struct X;\n");
    write("a/y.rs", "pub struct Y;\npub struct W;\nfn f() -> super::z::Z { todo!() }\n");
    write("a/z.rs", "//! see crate::a::x\npub struct Z;\nconst S: &str = \"crate::a::x\";\nfn g(c: char) -> bool { c == '\"' }\n#[cfg(test)]\nmod tests {\n    use crate::a::x::X;\n}\n");
    write("b.rs", "use crate::a::X;\n");
    let g = graph(&d);
    assert_eq!(g["a/x.rs"], BTreeSet::from(["a/y.rs".to_string()]));
    assert_eq!(g["a/z.rs"], BTreeSet::new(), "comments, strings and tests are not imports");
    assert_eq!(g["b.rs"], BTreeSet::from(["a/mod.rs".to_string()]));
    assert!(circles(&g).is_empty());
    write("a/z.rs", "pub struct Z;\nfn h() { let _ = crate::a::x::X; }\n");
    let want = ["a/x.rs", "a/y.rs", "a/z.rs"].map(String::from).to_vec();
    assert_eq!(circles(&graph(&d)), BTreeSet::from([want]));
}

/// `cargo test` runs no doctests and no unit-test harness of `main.rs` (Cargo.toml: `doctest =
/// false`, `test = false`, so that it links fewer binaries): this keeps that from hiding a test.
#[test]
fn no_test_hides_where_cargo_test_does_not_look() {
    let src = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src");
    let main = std::fs::read_to_string(src.join("main.rs")).unwrap();
    assert!(!main.contains("#[test]") && !main.contains("#[cfg(test)]"), "main.rs has tests: move them to the library");
    let mut files = Vec::new();
    rust_files(&src, &src, &mut files);
    for f in files {
        let text = std::fs::read_to_string(src.join(&f)).unwrap();
        let mut open = false;
        for (i, line) in text.lines().enumerate() {
            let doc = line.trim_start().strip_prefix("///").or_else(|| line.trim_start().strip_prefix("//!"));
            let Some(lang) = doc.map(str::trim).and_then(|d| d.strip_prefix("```")) else { continue };
            // An opening fence is Rust (a doctest) unless it names another language.
            let not_rust = ["text", "sh", "bash", "json", "toml", "console", "ignore"];
            assert!(
                open || not_rust.contains(&lang.trim()),
                "src/{f}:{}: a doc example (```{lang}) that `cargo test` would not run",
                i + 1
            );
            open = !open;
        }
    }
}
