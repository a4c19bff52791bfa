//! A stack-safety check run before any XML reaches a parser: XML parsers (urdf-rs's, roxmltree's
//! users, COLLADA readers) recurse per nested element, so a file nested a hundred thousand deep
//! would overflow the stack and abort the process. [`check_xml_nesting`] scans the text once,
//! without recursion, and refuses nesting deeper than [`XML_NESTING_LIMIT`] with the line.

/// The deepest element nesting trm's XML readers accept (URDF and SRDF nest 5 deep, COLLADA
/// scene graphs a few dozen).
pub const XML_NESTING_LIMIT: usize = 256;

/// Where an XML text nests too deep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TooDeep {
    /// Line (from 1) of the element that went past the limit.
    pub line: usize,
    /// The limit.
    pub limit: usize,
}

impl std::fmt::Display for TooDeep {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "line {}: elements nested more than {} deep",
            self.line, self.limit
        )
    }
}

/// Checks that no element of `text` is nested deeper than `limit`. Comments, CDATA sections,
/// processing instructions, declarations and quoted attribute values are skipped; a malformed
/// text passes whenever its nesting is shallow (the parser reports what is wrong with it).
pub fn check_xml_nesting(text: &[u8], limit: usize) -> Result<(), TooDeep> {
    let mut depth = 0usize;
    let mut line = 1usize;
    let mut i = 0;
    let n = text.len();
    // advances to just past `end`, counting lines; false at the end of the text
    let skip_to = |i: &mut usize, line: &mut usize, end: &[u8]| {
        while *i < n {
            if text[*i..].starts_with(end) {
                *i += end.len();
                return;
            }
            if text[*i] == b'\n' {
                *line += 1;
            }
            *i += 1;
        }
    };
    while i < n {
        match text[i] {
            b'\n' => {
                line += 1;
                i += 1;
            }
            b'<' => {
                let rest = &text[i..];
                if rest.starts_with(b"<!--") {
                    skip_to(&mut i, &mut line, b"-->");
                } else if rest.starts_with(b"<![CDATA[") {
                    skip_to(&mut i, &mut line, b"]]>");
                } else if rest.starts_with(b"<?") {
                    skip_to(&mut i, &mut line, b"?>");
                } else if rest.starts_with(b"<!") {
                    skip_to(&mut i, &mut line, b">");
                } else if rest.starts_with(b"</") {
                    depth = depth.saturating_sub(1);
                    skip_to(&mut i, &mut line, b">");
                } else {
                    let start_line = line;
                    // to the closing `>`, outside quoted attribute values
                    let mut quote = None;
                    let mut last = 0u8;
                    i += 1;
                    while i < n {
                        let c = text[i];
                        if c == b'\n' {
                            line += 1;
                        }
                        match quote {
                            Some(q) if c == q => quote = None,
                            Some(_) => {}
                            None if c == b'"' || c == b'\'' => quote = Some(c),
                            None if c == b'>' => break,
                            None => {}
                        }
                        if !c.is_ascii_whitespace() {
                            last = c;
                        }
                        i += 1;
                    }
                    i += 1;
                    if last != b'/' {
                        depth += 1;
                        if depth > limit {
                            return Err(TooDeep {
                                line: start_line,
                                limit,
                            });
                        }
                    }
                }
            }
            _ => i += 1,
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nested(n: usize) -> String {
        format!(
            "<robot>\n{}{}</robot>",
            "<a x='>'>".repeat(n),
            "</a>".repeat(n)
        )
    }

    #[test]
    fn nesting_up_to_the_limit_passes_and_one_more_is_refused_at_its_line() {
        assert!(check_xml_nesting(nested(9).as_bytes(), 10).is_ok());
        let e = check_xml_nesting(nested(10).as_bytes(), 10).unwrap_err();
        assert_eq!(e, TooDeep { line: 2, limit: 10 });
        assert!(e.to_string().contains("more than 10 deep"));
    }

    #[test]
    fn self_closing_elements_comments_and_cdata_do_not_nest() {
        let text = format!(
            "<?xml version='1.0'?><!DOCTYPE r><r>{}<!-- <a><a><a> -->\n<![CDATA[<b><b>]]></r>",
            "<a/><b x=\"/\" />".repeat(100)
        );
        assert!(check_xml_nesting(text.as_bytes(), 2).is_ok());
        let deep = "<a><b><c>";
        assert_eq!(check_xml_nesting(deep.as_bytes(), 2).unwrap_err().line, 1);
    }

    #[test]
    fn a_hundred_thousand_levels_are_refused_without_recursion() {
        assert!(check_xml_nesting(nested(100_000).as_bytes(), XML_NESTING_LIMIT).is_err());
    }
}
