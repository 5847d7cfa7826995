//! Writing the page: a small builder that escapes every text and attribute value and closes
//! every element it opens, so that the page is well-formed XML (XHTML syntax: void elements
//! self-closed, `&`, `<`, `>`, `"` and `'` as entities) whatever the scene names hold, as well
//! as HTML that any browser reads.

use std::path::Path;

/// `text` with the five XML special characters replaced by entities.
pub fn escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&#39;"),
            c => s.push(c),
        }
    }
    s
}

/// A relative path as a URL path: components joined with `/`, every byte other than ASCII
/// letters, digits and `-._~` percent-encoded (RFC 3986 unreserved characters), so that any
/// file name the run wrote is a valid link.
pub fn url(path: &Path) -> String {
    let mut parts = Vec::new();
    for c in path.components() {
        let text = c.as_os_str().to_string_lossy();
        let mut part = String::new();
        for b in text.bytes() {
            if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
                part.push(b as char);
            } else {
                part.push_str(&format!("%{b:02X}"));
            }
        }
        parts.push(part);
    }
    parts.join("/")
}

/// An XHTML document being written. Elements are opened and closed in order; the builder
/// keeps the stack, so a close always matches its open.
#[derive(Debug, Default)]
pub struct Html {
    out: String,
    open: Vec<&'static str>,
}

impl Html {
    /// An empty document (the caller starts with the doctype, [`Html::raw`]).
    pub fn new() -> Self {
        Self::default()
    }

    fn start_tag(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.out.push('<');
        self.out.push_str(tag);
        for (k, v) in attrs {
            self.out.push_str(&format!(" {k}=\"{}\"", escape(v)));
        }
    }

    /// Opens `<tag attrs…>`; attribute values are escaped.
    pub fn open(&mut self, tag: &'static str, attrs: &[(&str, &str)]) -> &mut Self {
        self.start_tag(tag, attrs);
        self.out.push('>');
        self.open.push(tag);
        self
    }

    /// A table's head row: one `<th class=…>` per `(class, head)`, an empty class omitted.
    pub fn head_row(&mut self, heads: &[(&str, &str)]) -> &mut Self {
        self.open("tr", &[]);
        for &(class, head) in heads {
            if class.is_empty() {
                self.element("th", &[], head);
            } else {
                self.element("th", &[("class", class)], head);
            }
        }
        self.close()
    }

    /// Closes the innermost open element.
    ///
    /// # Panics
    /// If no element is open (a bug in the page's code, not in its input).
    pub fn close(&mut self) -> &mut Self {
        let tag = self.open.pop().expect("close without an open element");
        self.out.push_str(&format!("</{tag}>"));
        if matches!(
            tag,
            "section" | "table" | "tr" | "figure" | "div" | "details" | "ul" | "ol" | "li"
        ) {
            self.out.push('\n');
        }
        self
    }

    /// A void element, self-closed: `<tag attrs…/>` (`img`, `br`, `meta`, `input`).
    pub fn void(&mut self, tag: &str, attrs: &[(&str, &str)]) -> &mut Self {
        self.start_tag(tag, attrs);
        self.out.push_str("/>");
        self
    }

    /// Escaped text.
    pub fn text(&mut self, text: &str) -> &mut Self {
        self.out.push_str(&escape(text));
        self
    }

    /// `<tag attrs…>text</tag>`.
    pub fn element(&mut self, tag: &'static str, attrs: &[(&str, &str)], text: &str) -> &mut Self {
        self.open(tag, attrs).text(text).close()
    }

    /// Markup written as is: only for the page's own constant parts (doctype, style sheet),
    /// never for anything from the input.
    pub fn raw(&mut self, markup: &'static str) -> &mut Self {
        self.out.push_str(markup);
        self
    }

    /// The document.
    ///
    /// # Panics
    /// If an element is still open.
    pub fn finish(self) -> String {
        assert!(self.open.is_empty(), "unclosed elements: {:?}", self.open);
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_and_attributes_are_escaped_and_links_encoded() {
        assert_eq!(
            escape(r#"<a & "b" 'c'>"#),
            "&lt;a &amp; &quot;b&quot; &#39;c&#39;&gt;"
        );
        assert_eq!(url(Path::new("a b/<x>&y.png")), "a%20b/%3Cx%3E%26y.png");
        assert_eq!(
            url(Path::new("scene/hard-sv/image.png")),
            "scene/hard-sv/image.png"
        );
        let mut h = Html::new();
        h.open("p", &[("title", "<&>")])
            .text("1 < 2 & 3")
            .void("br", &[])
            .close();
        assert_eq!(
            h.finish(),
            "<p title=\"&lt;&amp;&gt;\">1 &lt; 2 &amp; 3<br/></p>"
        );
    }

    #[test]
    #[should_panic(expected = "unclosed")]
    fn an_unclosed_element_is_a_bug() {
        let mut h = Html::new();
        h.open("div", &[]);
        h.finish();
    }
}
