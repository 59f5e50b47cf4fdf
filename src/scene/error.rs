//! The scene layer's errors: [`SceneError`] (a file, a 1-based line and a message) and [`LineError`],
//! the message of one bad line before the parser knows where it is.

use std::path::{Path, PathBuf};

/// A scene-file error: file, 1-based line (0 when not tied to a line), and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}: {message}", .file.display(), line_suffix(.line))]
pub struct SceneError {
    /// The file being parsed.
    pub file: PathBuf,
    /// 1-based line number; 0 when the error is not tied to a line (e.g. the file cannot be read).
    pub line: usize,
    /// What went wrong and what was expected.
    pub message: String,
}

/// `:LINE` for a line number, nothing for line 0.
fn line_suffix(line: &usize) -> String {
    if *line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

impl SceneError {
    /// An error in `file` at 1-based `line` (0: not tied to a line).
    pub fn new(file: &Path, line: usize, message: impl Into<String>) -> Self {
        Self { file: file.to_path_buf(), line, message: message.into() }
    }
}

/// What is wrong with one command or value, before a file and line are attached
/// ([`LineError::at`]); its text is the message of the [`SceneError`] it becomes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct LineError(pub String);

impl LineError {
    /// The scene error this becomes in `file` at 1-based `line`.
    pub fn at(self, file: &Path, line: usize) -> SceneError {
        SceneError::new(file, line, self.0)
    }
}

impl From<String> for LineError {
    fn from(message: String) -> Self {
        Self(message)
    }
}

impl From<&str> for LineError {
    fn from(message: &str) -> Self {
        Self(message.to_string())
    }
}
