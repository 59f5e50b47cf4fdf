//! The text of an OBJ or MTL file: read within a size bound and decoded (UTF-8, Latin-1 with a
//! warning, refused UTF-16). Both the OBJ reader ([`super::read`]) and the MTL reader
//! ([`super::mtl`]) start here.

use super::{err, warn, ObjWarning};
use crate::scene::error::SceneError;
use crate::scene::limits::read_bounded;
use std::borrow::Cow;
use std::path::Path;

/// Decoded text of an OBJ/MTL file: UTF-8 (a BOM dropped), else Latin-1 (one char per byte) with
/// the line of the first byte that is not UTF-8. UTF-16 (a UTF-16 BOM or NUL bytes) is refused with
/// the line where it shows.
fn decode(bytes: &[u8]) -> Result<(Cow<'_, str>, Option<usize>), (usize, String)> {
    let line_at = |i: usize| bytes[..i].iter().filter(|&&b| b == b'\n').count() + 1;
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    if bytes.starts_with(b"\xfe\xff") || bytes.starts_with(b"\xff\xfe") {
        return Err((1, "the file is not valid UTF-8 text (it is UTF-16; save it as UTF-8)".into()));
    }
    if let Some(i) = bytes.iter().position(|&b| b == 0) {
        return Err((line_at(i), "the file is not valid UTF-8 text (a NUL byte: UTF-16 or binary?)".into()));
    }
    match std::str::from_utf8(bytes) {
        Ok(t) => Ok((Cow::Borrowed(t), None)),
        Err(e) => Ok((Cow::Owned(bytes.iter().map(|&b| b as char).collect()), Some(line_at(e.valid_up_to())))),
    }
}

pub(super) const LATIN1: &str = "the file is not valid UTF-8 text; read as Latin-1";

/// Reads and decodes `path` (at most `max` bytes, [`read_bounded`]); `what` names the file kind in
/// the "cannot read" error.
pub(super) fn read_text(
    path: &Path,
    what: &str,
    max: u64,
    warnings: &mut Vec<ObjWarning>,
) -> Result<(String, bool), SceneError> {
    let bytes = read_bounded(path, what, max).map_err(|(line, m)| err(path, line, m))?;
    let (text, latin1) = decode(&bytes).map_err(|(line, m)| err(path, line, m))?;
    if let Some(line) = latin1 {
        warnings.push(warn(path, line, format!("{LATIN1} (ISO 8859-1)")));
    }
    Ok((text.into_owned(), latin1.is_some()))
}
