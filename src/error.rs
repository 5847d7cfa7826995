//! The one error type user input can produce. Every variant names the file (or built-in
//! scene), the object and the problem; the CLI prints it on one line and exits with code 2.

use std::fmt::{self, Write};

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
    /// `file: object: message` (or `file: message`) on one line: control characters in any
    /// part (a newline in a quoted path, say) are written escaped, e.g. `\n`, and a part
    /// longer than [`MAX_SHOWN_CHARS`] is shortened ([`shortened`]).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write_one_line(f, &self.file)?;
        if let Some(o) = &self.object {
            f.write_str(": ")?;
            write_one_line(f, o)?;
        }
        f.write_str(": ")?;
        write_one_line(f, &self.message)
    }
}

/// The longest text (a path, say) a message shows in full, in characters.
pub const MAX_SHOWN_CHARS: usize = 1000;

/// `s` as a message shows it: unchanged up to [`MAX_SHOWN_CHARS`] characters, else its first
/// 600 and last 300 characters around a note saying how long it was, e.g.
/// `aaa…[10485760 characters, shortened]…bbb`.
pub fn shortened(s: &str) -> std::borrow::Cow<'_, str> {
    let n = s.chars().count();
    if n <= MAX_SHOWN_CHARS {
        return s.into();
    }
    let head: String = s.chars().take(600).collect();
    let tail: String = s.chars().skip(n - 300).collect();
    format!("{head}…[{n} characters, shortened]…{tail}").into()
}

/// Writes `s` [`shortened`], with every control character escaped (`\n`, `\r`, `\t`,
/// `\u{..}`).
fn write_one_line(f: &mut fmt::Formatter<'_>, s: &str) -> fmt::Result {
    for c in shortened(s).chars() {
        if c.is_control() {
            write!(f, "{}", c.escape_default())?;
        } else {
            f.write_char(c)?;
        }
    }
    Ok(())
}

impl std::error::Error for InputError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_is_one_line() {
        let e = InputError::at("a\nb.toml", "light.texture", "cannot open x\r\ny.png");
        assert_eq!(
            e.to_string(),
            "a\\nb.toml: light.texture: cannot open x\\r\\ny.png"
        );
        assert_eq!(InputError::new("f", "m").to_string(), "f: m");
    }

    #[test]
    fn long_parts_are_shortened_and_say_so() {
        let path = format!("/{}x.toml", "a/".repeat(5_000_000));
        let e = InputError::new(&path, "cannot read scene file").to_string();
        assert!(e.len() < 1000, "{} bytes", e.len());
        assert!(
            e.starts_with("/a/a/")
                && e.contains("…[10000007 characters, shortened]…")
                && e.ends_with("a/a/x.toml: cannot read scene file"),
            "{e}"
        );
        let fits = "b".repeat(MAX_SHOWN_CHARS);
        assert_eq!(
            InputError::new(&fits, "m").to_string(),
            format!("{fits}: m")
        );
    }
}
