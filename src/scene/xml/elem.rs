//! The element tree a Mitsuba XML document is read into ([`Elem`], each with its [`Loc`]): what
//! the reader ([`super::doc`]) builds, the 0.6 upgrade ([`super::upgrade`]) rewrites and the
//! plugins read.

use crate::scene::error::SceneError;
use std::path::PathBuf;
use std::sync::Arc;

/// Where an element is: its file and 1-based line.
#[derive(Clone, Debug, PartialEq)]
pub struct Loc {
    /// the file the element is in (an included file, not the scene, when it came from one)
    pub file: Arc<PathBuf>,
    /// 1-based line
    pub line: usize,
}

impl Loc {
    /// A [`SceneError`] at this place.
    pub fn err(&self, message: impl Into<String>) -> SceneError {
        SceneError::new(&self.file, self.line, message)
    }

    /// `file:line`, for warnings.
    pub fn show(&self) -> String {
        format!("{}:{}", self.file.display(), self.line)
    }
}

/// One element after reading: tag, attributes (parameters substituted), children (includes
/// inlined, `<default>` and `<path>` consumed).
#[derive(Clone, Debug, PartialEq)]
pub struct Elem {
    /// tag name
    pub tag: String,
    /// attributes in document order
    pub attrs: Vec<(String, String)>,
    /// child elements
    pub children: Vec<Elem>,
    /// where it is
    pub at: Loc,
}

impl Elem {
    /// The value of attribute `name`, if present.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    /// The value of attribute `name`, or an error naming the element.
    pub fn need(&self, name: &str) -> Result<&str, SceneError> {
        self.attr(name).ok_or_else(|| self.at.err(format!("<{}> needs a `{name}` attribute", self.tag)))
    }

    /// `<tag type="...">` as text, for messages.
    pub fn what(&self) -> String {
        match self.attr("type") {
            Some(t) => format!("<{} type=\"{t}\">", self.tag),
            None => format!("<{}>", self.tag),
        }
    }
}
