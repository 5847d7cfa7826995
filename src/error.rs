//! The one error type user input can produce. Every variant names the file (or built-in
//! scene), the object and the problem; the CLI prints it on one line and exits with code 2.

use std::fmt;

/// A problem with user input: a scene file, an OBJ, an option, a command-line argument.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputError {
    /// The scene file, OBJ file or built-in scene name the problem is in.
    pub file: String,
    /// The object inside it (e.g. `meshes[2] (bunny.obj)`, `light`, `options.nsample.n`), if any.
    pub object: Option<String>,
    /// What is wrong, in words a user can act on.
    pub message: String,
}

impl InputError {
    /// An error about `file` as a whole.
    pub fn new(file: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: file.into(),
            object: None,
            message: message.into(),
        }
    }

    /// An error about one `object` inside `file`.
    pub fn at(
        file: impl Into<String>,
        object: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            file: file.into(),
            object: Some(object.into()),
            message: message.into(),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.object {
            Some(o) => write!(f, "{}: {}: {}", self.file, o, self.message),
            None => write!(f, "{}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for InputError {}
