//! Reading Mitsuba XML into an owned element tree: the file read under the size limit, parsed by
//! `roxmltree` (no DTD, so no entity expansion), `<include>` inlined (loop and depth checked),
//! `<default>` and `-D` parameters substituted for `$name`, `<path>` search directories, and
//! Mitsuba's upgrade of 0.6-format files (camelCase names to snake_case).

pub use super::elem::{Elem, Loc};
use crate::scene::error::SceneError;
use crate::scene::limits::{read_bounded, Limits};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Deepest element nesting accepted (a scene nests a handful of levels; this stops a hostile
/// file from exhausting the stack).
pub const MAX_NESTING: usize = 64;
/// Deepest chain of `<include>`s accepted.
pub const MAX_INCLUDE_DEPTH: usize = 16;
/// Most XML nodes accepted in one file (roxmltree's own cap).
pub const MAX_NODES: u32 = 1 << 22;

/// The reader's state across the scene and its includes.
pub struct Reader<'a> {
    limits: &'a Limits,
    /// parameters: `-D` first (they win over `<default>`), then defaults as met
    params: HashMap<String, String>,
    /// directories searched for relative file names, most recent `<path>` first
    pub search: Vec<PathBuf>,
    /// files being included (canonical paths), outermost first
    stack: Vec<PathBuf>,
}

/// A file's text, read within the file-size limit, as a [`SceneError`] on failure.
pub fn read_text(path: &Path, what: &str, limits: &Limits) -> Result<String, SceneError> {
    let bytes = read_bounded(path, what, limits.max_file_bytes).map_err(|(l, m)| SceneError::new(path, l, m))?;
    String::from_utf8(bytes).map_err(|e| SceneError::new(path, 0, format!("the file is not valid UTF-8 text ({e})")))
}

impl<'a> Reader<'a> {
    /// A reader with the command line's `-D name=value` parameters.
    pub fn new(limits: &'a Limits, defines: &[(String, String)]) -> Self {
        Self { limits, params: defines.iter().cloned().collect(), search: Vec::new(), stack: Vec::new() }
    }

    /// Reads the scene file `path`: the root `<scene>` element, expanded.
    pub fn read_scene(&mut self, path: &Path) -> Result<Elem, SceneError> {
        if let Some(dir) = path.parent() {
            self.search.push(dir.to_path_buf());
        }
        let mut root = self.read_file(path, None)?;
        let children = std::mem::take(&mut root.children);
        root.children = self.expand_children(children, 1)?;
        Ok(root)
    }

    /// Finds a file named in the scene: absolute, or relative to a `<path>` directory or the
    /// scene's directory (most recent first), as Mitsuba's resolver does.
    pub fn resolve(&self, name: &str) -> PathBuf {
        resolve_in(&self.search, name)
    }

    /// Parses one file into an unexpanded tree (root `<scene>`, upgraded when it is 0.6).
    fn read_file(&mut self, path: &Path, from: Option<&Loc>) -> Result<Elem, SceneError> {
        let text = read_text(path, "the XML file", self.limits).map_err(|e| match from {
            Some(at) => at.err(format!("cannot include {}: {}", path.display(), e.message)),
            None => e,
        })?;
        let opts = roxmltree::ParsingOptions { allow_dtd: false, nodes_limit: MAX_NODES, ..Default::default() };
        let doc = roxmltree::Document::parse_with_options(&text, opts).map_err(|e| {
            let pos = e.pos();
            let hint = match e {
                roxmltree::Error::DtdDetected => " (a DTD or entity declaration is refused)",
                _ => "",
            };
            SceneError::new(path, pos.row as usize, format!("malformed XML: {e}{hint}"))
        })?;
        let file = Arc::new(path.to_path_buf());
        let root = doc.root_element();
        let mut elem = own(&doc, root, &file, 0)?;
        if elem.tag != "scene" {
            return Err(elem.at.err(format!("the root element is <{}>, not <scene>", elem.tag)));
        }
        let version = elem.need("version")?;
        let major = parse_version(version)
            .ok_or_else(|| elem.at.err(format!("version \"{version}\" is not a version number like \"3.0.0\"")))?;
        if major < 2 {
            super::upgrade::upgrade(&mut elem);
        }
        Ok(elem)
    }

    /// Expands the children of one element: parameters substituted, `<default>`, `<path>` and
    /// `<include>` handled in document order.
    fn expand_children(&mut self, children: Vec<Elem>, depth: usize) -> Result<Vec<Elem>, SceneError> {
        let mut out = Vec::with_capacity(children.len());
        for mut e in children {
            self.substitute(&mut e)?;
            match e.tag.as_str() {
                "default" => {
                    let name = e.need("name")?.to_string();
                    let value = e.need("value")?.to_string();
                    if depth != 1 {
                        return Err(e.at.err("<default> must be a direct child of <scene>"));
                    }
                    self.params.entry(name).or_insert(value);
                }
                "path" => {
                    let v = e.need("value")?;
                    let dir = e.at.file.parent().map_or_else(|| PathBuf::from(v), |d| d.join(v));
                    self.search.push(dir);
                }
                "include" => {
                    let name = e.need("filename")?;
                    let path = self.resolve(name);
                    let canon = path
                        .canonicalize()
                        .map_err(|err| e.at.err(format!("cannot include {}: {err}", path.display())))?;
                    if self.stack.contains(&canon) {
                        return Err(e.at.err(format!("include loop: {} includes itself", path.display())));
                    }
                    if self.stack.len() >= MAX_INCLUDE_DEPTH {
                        return Err(e.at.err(format!("includes nest deeper than {MAX_INCLUDE_DEPTH} files")));
                    }
                    self.stack.push(canon);
                    let inc = self.read_file(&path, Some(&e.at))?;
                    let kids = self.expand_children(inc.children, depth)?;
                    self.stack.pop();
                    out.extend(kids);
                }
                _ => {
                    let kids = std::mem::take(&mut e.children);
                    e.children = self.expand_children(kids, depth + 1)?;
                    out.push(e);
                }
            }
        }
        Ok(out)
    }

    /// Replaces `$name` in every attribute of `e` by the parameter's value.
    fn substitute(&self, e: &mut Elem) -> Result<(), SceneError> {
        for (_, v) in &mut e.attrs {
            if !v.contains('$') {
                continue;
            }
            let mut out = String::with_capacity(v.len());
            let mut rest = v.as_str();
            while let Some(i) = rest.find('$') {
                out.push_str(&rest[..i]);
                let tail = &rest[i + 1..];
                let n = tail.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(tail.len());
                let name = &tail[..n];
                let value = self.params.get(name).ok_or_else(|| {
                    e.at.err(format!(
                        "undefined parameter ${name} (give it with -D {name}=VALUE or <default name=\"{name}\" value=\"...\"/>)"
                    ))
                })?;
                out.push_str(value);
                rest = &tail[n..];
            }
            out.push_str(rest);
            *v = out;
        }
        Ok(())
    }
}

/// The major number of a `version="M.m.p"` attribute.
fn parse_version(v: &str) -> Option<u32> {
    let mut parts = v.trim().split('.');
    let major = parts.next()?.parse().ok()?;
    parts.all(|p| p.parse::<u32>().is_ok()).then_some(major)
}

/// An owned copy of `node` and its element children (text and comments dropped), refusing
/// nesting deeper than [`MAX_NESTING`].
fn own(
    doc: &roxmltree::Document,
    node: roxmltree::Node,
    file: &Arc<PathBuf>,
    depth: usize,
) -> Result<Elem, SceneError> {
    let line = doc.text_pos_at(node.range().start).row as usize;
    let at = Loc { file: file.clone(), line };
    if depth > MAX_NESTING {
        return Err(at.err(format!("elements nest deeper than {MAX_NESTING} levels")));
    }
    let mut children = Vec::new();
    for c in node.children() {
        if c.is_element() {
            children.push(own(doc, c, file, depth + 1)?);
        } else if c.is_text() && c.text().is_some_and(|t| !t.trim().is_empty()) {
            let at = Loc { file: file.clone(), line: doc.text_pos_at(c.range().start).row as usize };
            return Err(at.err(format!("unexpected text inside <{}>", node.tag_name().name())));
        }
    }
    let attrs = node.attributes().map(|a| (a.name().to_string(), a.value().to_string())).collect();
    Ok(Elem { tag: node.tag_name().name().to_string(), attrs, children, at })
}

/// A file named in a scene, found as Mitsuba's resolver finds it: absolute, or the first of the
/// search directories (most recent first) that has it, else relative to the first directory.
pub fn resolve_in(search: &[PathBuf], name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    search
        .iter()
        .rev()
        .map(|d| d.join(p))
        .find(|c| c.exists())
        .unwrap_or_else(|| search.first().map_or_else(|| p.to_path_buf(), |d| d.join(p)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    fn read(path: &Path, defines: &[(String, String)]) -> Result<Elem, SceneError> {
        let limits = Limits::default();
        Reader::new(&limits, defines).read_scene(path)
    }

    #[test]
    fn defaults_substitution_and_command_line() {
        let d = tempfile::tempdir().unwrap();
        let p = write(
            d.path(),
            "a.xml",
            "<scene version=\"3.0.0\">\n<default name=\"spp\" value=\"32\"/>\n<integer name=\"n\" value=\"$spp\"/>\n</scene>",
        );
        let e = read(&p, &[]).unwrap();
        assert_eq!(e.children.len(), 1);
        assert_eq!(e.children[0].attr("value"), Some("32"));
        assert_eq!(e.children[0].at.line, 3);
        let e = read(&p, &[("spp".into(), "7".into())]).unwrap();
        assert_eq!(e.children[0].attr("value"), Some("7"));
        let q = write(d.path(), "b.xml", "<scene version=\"3.0.0\">\n<integer name=\"n\" value=\"$nope\"/>\n</scene>");
        let err = read(&q, &[]).unwrap_err();
        assert_eq!(err.line, 2);
        assert!(err.message.contains("undefined parameter $nope"), "{err}");
    }

    #[test]
    fn includes_inline_and_loops_are_refused() {
        let d = tempfile::tempdir().unwrap();
        write(d.path(), "frag.xml", "<scene version=\"3.0.0\"><float name=\"x\" value=\"1\"/></scene>");
        let p = write(d.path(), "a.xml", "<scene version=\"3.0.0\"><include filename=\"frag.xml\"/></scene>");
        let e = read(&p, &[]).unwrap();
        assert_eq!(e.children[0].tag, "float");
        assert!(e.children[0].at.file.ends_with("frag.xml"));
        let l = write(d.path(), "loop.xml", "<scene version=\"3.0.0\">\n<include filename=\"loop.xml\"/></scene>");
        let err = read(&l, &[]).unwrap_err();
        assert!(err.message.contains("include loop"), "{err}");
        let m = write(d.path(), "m.xml", "<scene version=\"3.0.0\">\n<include filename=\"missing.xml\"/></scene>");
        let err = read(&m, &[]).unwrap_err();
        assert_eq!(err.line, 2);
        assert!(err.message.contains("cannot include"), "{err}");
    }

    #[test]
    fn hostile_documents_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let bomb = "<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [<!ENTITY lol \"lol\"><!ENTITY lol2 \"&lol;&lol;\">]>\n<scene version=\"3.0.0\">&lol2;</scene>";
        let err = read(&write(d.path(), "bomb.xml", bomb), &[]).unwrap_err();
        assert!(err.message.contains("DTD"), "{err}");
        let deep = format!("<scene version=\"3.0.0\">{}{}</scene>", "<a>".repeat(200), "</a>".repeat(200));
        let err = read(&write(d.path(), "deep.xml", &deep), &[]).unwrap_err();
        assert!(err.message.contains("nest deeper"), "{err}");
        let err =
            read(&write(d.path(), "bad.xml", "<scene version=\"3.0.0\">\n<float name=\"x\"></floaty></scene>"), &[])
                .unwrap_err();
        assert!(err.message.contains("malformed XML") && err.line == 2, "{err}");
        let err = read(&write(d.path(), "v.xml", "<scene>\n</scene>"), &[]).unwrap_err();
        assert!(err.message.contains("version"), "{err}");
    }
}
