//! Where a field path (`solver.sigma`, `costs[2].cost.part`, `world.objects[1].xyz`) sits in
//! RON text, so that an error found after parsing points at the line and column it is about.
//!
//! The text is scanned once into a light tree of structs, sequences and maps with positions;
//! comments, strings and raw strings are skipped. A path segment is a field name or an index
//! (`[k]`); a field looked up on a one-element sequence (`Some((…))`, `Position(…)` used as a
//! newtype) looks inside it, so paths need not spell out `Some`.

/// 1-based (line, column) of `path` in `text`: the field's key, or a sequence element's first
/// character. `None` when the text does not hold the path (or is not RON enough to scan).
///
/// ```
/// use trm_io::locate_ron_path;
/// let text = "(\n  noise: Some((sigma: 0.1)),\n  solver: (algo: \"xnes\", sigma: -1.0),\n)";
/// assert_eq!(locate_ron_path(text, "solver.sigma"), Some((3, 26)));
/// assert_eq!(locate_ron_path(text, "noise.sigma"), Some((2, 16)));
/// assert_eq!(locate_ron_path(text, "solver.population"), None);
/// ```
pub fn locate_ron_path(text: &str, path: &str) -> Option<(usize, usize)> {
    let mut scanner = Scanner {
        bytes: text.as_bytes(),
        at: 0,
    };
    let root = scanner.value(0)?;
    let mut node = &root;
    let mut position = root.start;
    for segment in segments(path)? {
        let (next, at) = node.child(&segment)?;
        node = next;
        position = at;
    }
    Some(line_column(text, position))
}

/// A RON parse error explained for people: where, what, and how to fix it (the closest valid
/// names for an unknown field or variant).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RonProblem {
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong.
    pub problem: String,
    /// What to do about it (may be empty).
    pub fix: String,
}

impl RonProblem {
    /// The problem and its fix in one line (`unknown field `x`; did you mean `y`?`).
    pub fn message(&self) -> String {
        if self.fix.is_empty() {
            self.problem.clone()
        } else {
            format!("{}; {}", self.problem, self.fix)
        }
    }
}

/// Explains a RON parse error (the one reader behind every RON file of trm: model
/// descriptions, worlds, task specs, motion specs).
pub fn explain_ron_error(e: &ron::error::SpannedError) -> RonProblem {
    use ron::error::Error as E;
    let suggestion = |found: &str, expected: &[&str]| {
        let near = crate::closest_names(found, expected.iter().copied());
        if near.is_empty() {
            format!("expected one of `{}`", expected.join("`, `"))
        } else {
            format!(
                "did you mean `{}`? (expected one of `{}`)",
                near.join("`, `"),
                expected.join("`, `")
            )
        }
    };
    let (problem, fix) = match &e.code {
        E::NoSuchEnumVariant {
            expected, found, ..
        } => (
            format!("unknown variant `{found}`"),
            suggestion(found, expected),
        ),
        E::NoSuchStructField {
            expected, found, ..
        } => (
            format!("unknown field `{found}`"),
            suggestion(found, expected),
        ),
        E::MissingStructField { field, .. } => (
            format!("missing field `{field}`"),
            format!("add `{field}: ...`"),
        ),
        E::DuplicateStructField { field, .. } => {
            (format!("field `{field}` is given twice"), "keep one".into())
        }
        other => (other.to_string(), String::new()),
    };
    RonProblem {
        line: e.span.start.line,
        column: e.span.start.col,
        problem,
        fix,
    }
}

/// An error located in a spec file (task specs, motion specs, task-map specs): the file, the
/// line and column, the field path, the problem and its fix. The one shape of every spec error
/// of trm.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{origin}{}: {field}: {problem}{}", position.map(|(l, c)| format!(":{l}:{c}")).unwrap_or_default(), if fix.is_empty() { String::new() } else { format!("; fix: {fix}") })]
pub struct SpecError {
    /// The spec file (or `<string>`).
    pub origin: String,
    /// 1-based (line, column) of the field, when the text spells it out.
    pub position: Option<(usize, usize)>,
    /// Field path, e.g. `costs[2].cost.part`.
    pub field: String,
    /// What is wrong.
    pub problem: String,
    /// What to do about it (may be empty).
    pub fix: String,
}

impl SpecError {
    /// An error at field path `field` of spec `text`, located at that path or at the nearest
    /// ancestor the text spells out (a field left at its default is not written).
    pub fn at(
        text: &str,
        origin: &str,
        field: &str,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> Self {
        SpecError {
            origin: origin.to_string(),
            position: locate_ron_field(text, field),
            field: field.to_string(),
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    /// A RON parse error of spec `origin`, explained ([`explain_ron_error`]).
    pub fn from_ron(e: &ron::error::SpannedError, origin: &str) -> Self {
        let p = explain_ron_error(e);
        SpecError {
            origin: origin.to_string(),
            position: Some((p.line, p.column)),
            field: "spec".into(),
            problem: p.problem,
            fix: p.fix,
        }
    }
}

/// [`locate_ron_path`] of `field`, or of its nearest ancestor the text spells out (a field left
/// at its default is not written): where an error about `field` should point.
pub fn locate_ron_field(text: &str, field: &str) -> Option<(usize, usize)> {
    let mut path = field;
    loop {
        if let Some(at) = locate_ron_path(text, path) {
            return Some(at);
        }
        path = &path[..path.rfind(['.', '['])?];
    }
}

/// One step of a path.
#[derive(Debug, PartialEq)]
enum Segment {
    Field(String),
    Index(usize),
}

fn segments(path: &str) -> Option<Vec<Segment>> {
    let mut out = Vec::new();
    for part in path.split('.').filter(|p| !p.is_empty()) {
        let (name, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !name.is_empty() {
            out.push(Segment::Field(name.to_string()));
        }
        while let Some(stripped) = rest.strip_prefix('[') {
            let end = stripped.find(']')?;
            out.push(Segment::Index(stripped[..end].trim().parse().ok()?));
            rest = &stripped[end + 1..];
        }
    }
    Some(out)
}

/// A scanned value: where it starts and what it holds.
#[derive(Debug)]
struct Node {
    start: usize,
    kind: Kind,
}

#[derive(Debug)]
enum Kind {
    /// `(a: x, b: y)` or `Name(a: x)`: (key, key position, value).
    Struct(Vec<(String, usize, Node)>),
    /// `[x, y]`, `(x, y)` or `Name(x)`.
    Seq(Vec<Node>),
    /// `{key: value}`: (key text without quotes, key position, value).
    Map(Vec<(String, usize, Node)>),
    /// Anything else (numbers, strings, identifiers, unit variants).
    Atom,
}

impl Node {
    fn child(&self, segment: &Segment) -> Option<(&Node, usize)> {
        match (&self.kind, segment) {
            (Kind::Struct(fields), Segment::Field(name))
            | (Kind::Map(fields), Segment::Field(name)) => fields
                .iter()
                .find(|(k, ..)| k == name)
                .map(|(_, at, v)| (v, *at)),
            (Kind::Seq(items), Segment::Index(i)) => items.get(*i).map(|v| (v, v.start)),
            // a newtype wrapper (`Some(…)`, a variant holding one struct) is looked through
            (Kind::Seq(items), Segment::Field(_)) if items.len() == 1 => items[0].child(segment),
            _ => None,
        }
    }
}

struct Scanner<'a> {
    bytes: &'a [u8],
    at: usize,
}

const MAX_DEPTH: usize = 256;

impl Scanner<'_> {
    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.at).copied()
    }

    /// Skips whitespace and comments.
    fn skip(&mut self) {
        loop {
            match self.peek() {
                Some(c) if c.is_ascii_whitespace() => self.at += 1,
                Some(b'/') if self.bytes.get(self.at + 1) == Some(&b'/') => {
                    while self.peek().is_some_and(|c| c != b'\n') {
                        self.at += 1;
                    }
                }
                Some(b'/') if self.bytes.get(self.at + 1) == Some(&b'*') => {
                    self.at += 2;
                    while self.at < self.bytes.len()
                        && !(self.bytes[self.at] == b'*'
                            && self.bytes.get(self.at + 1) == Some(&b'/'))
                    {
                        self.at += 1;
                    }
                    self.at = (self.at + 2).min(self.bytes.len());
                }
                _ => return,
            }
        }
    }

    fn string(&mut self) {
        // at the opening quote
        self.at += 1;
        while let Some(c) = self.peek() {
            self.at += 1;
            match c {
                b'\\' => self.at += 1,
                b'"' => return,
                _ => {}
            }
        }
    }

    fn raw_string(&mut self) {
        // at `r`, then `#…#"`
        self.at += 1;
        let mut hashes = 0;
        while self.peek() == Some(b'#') {
            hashes += 1;
            self.at += 1;
        }
        self.at += 1; // the quote
        while self.at < self.bytes.len() {
            if self.bytes[self.at] == b'"'
                && self.bytes[self.at + 1..]
                    .iter()
                    .take(hashes)
                    .filter(|&&c| c == b'#')
                    .count()
                    == hashes
            {
                self.at += 1 + hashes;
                return;
            }
            self.at += 1;
        }
    }

    fn identifier(&mut self) -> String {
        let start = self.at;
        while self
            .peek()
            .is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_')
        {
            self.at += 1;
        }
        String::from_utf8_lossy(&self.bytes[start..self.at]).into_owned()
    }

    fn value(&mut self, depth: usize) -> Option<Node> {
        if depth > MAX_DEPTH {
            return None;
        }
        self.skip();
        let start = self.at;
        let kind = match self.peek()? {
            b'(' => self.parenthesised(depth)?,
            b'[' => Kind::Seq(self.sequence(b']', depth)?),
            b'{' => self.map(depth)?,
            b'"' => {
                self.string();
                Kind::Atom
            }
            b'r' if matches!(self.bytes.get(self.at + 1), Some(b'#') | Some(b'"')) => {
                self.raw_string();
                Kind::Atom
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                self.identifier();
                self.skip();
                if self.peek() == Some(b'(') {
                    self.parenthesised(depth)?
                } else {
                    Kind::Atom
                }
            }
            _ => {
                // numbers, chars, signs: up to the next delimiter
                while self.peek().is_some_and(|c| {
                    !matches!(c, b',' | b')' | b']' | b'}' | b':') && !c.is_ascii_whitespace()
                }) {
                    self.at += 1;
                }
                if self.at == start {
                    // a delimiter where a value belongs (`(:`, `[}`): malformed, and no
                    // progress would be made
                    return None;
                }
                Kind::Atom
            }
        };
        Some(Node { start, kind })
    }

    /// `( … )`: a struct when its first entry is `identifier:`, else a sequence.
    fn parenthesised(&mut self, depth: usize) -> Option<Kind> {
        let open = self.at;
        self.at += 1;
        self.skip();
        let first = self.at;
        let is_struct = if self
            .peek()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == b'_')
        {
            self.identifier();
            self.skip();
            self.peek() == Some(b':')
        } else {
            false
        };
        self.at = open;
        if !is_struct {
            return Some(Kind::Seq(self.sequence(b')', depth)?));
        }
        self.at = first;
        let mut fields = Vec::new();
        loop {
            self.skip();
            match self.peek()? {
                b')' => {
                    self.at += 1;
                    return Some(Kind::Struct(fields));
                }
                b',' => self.at += 1,
                _ => {
                    let key_at = self.at;
                    let key = self.identifier();
                    if key.is_empty() {
                        return None;
                    }
                    self.skip();
                    if self.peek()? != b':' {
                        return None;
                    }
                    self.at += 1;
                    let value = self.value(depth + 1)?;
                    fields.push((key, key_at, value));
                }
            }
        }
    }

    /// Elements up to `close`, the opening bracket at `self.at`.
    fn sequence(&mut self, close: u8, depth: usize) -> Option<Vec<Node>> {
        self.at += 1;
        let mut items = Vec::new();
        loop {
            self.skip();
            match self.peek()? {
                c if c == close => {
                    self.at += 1;
                    return Some(items);
                }
                b',' => self.at += 1,
                _ => items.push(self.value(depth + 1)?),
            }
        }
    }

    fn map(&mut self, depth: usize) -> Option<Kind> {
        self.at += 1;
        let mut entries = Vec::new();
        loop {
            self.skip();
            match self.peek()? {
                b'}' => {
                    self.at += 1;
                    return Some(Kind::Map(entries));
                }
                b',' => self.at += 1,
                _ => {
                    let key_at = self.at;
                    let key_node = self.value(depth + 1)?;
                    let raw =
                        String::from_utf8_lossy(&self.bytes[key_node.start..self.at]).into_owned();
                    self.skip();
                    if self.peek()? != b':' {
                        return None;
                    }
                    self.at += 1;
                    let value = self.value(depth + 1)?;
                    entries.push((raw.trim().trim_matches('"').to_string(), key_at, value));
                }
            }
        }
    }
}

fn line_column(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = r##"// a comment with solver: (sigma: 3)
(
    model: "icub_upper_body",
    noise: Some((samples: 4, sigma: 0.1, seed: 2)),
    world: (objects: [
        (name: "table", shape: Box(size: (0.5, 0.8, 0.04)), xyz: (-0.4, 0.0, -0.14)),
        (name: "cup", shape: Sphere(radius: 0.03), xyz: (-0.3, 0.1, 0.0)),
    ]),
    costs: [
        (weight: 0.1, cost: HomePosture(weights: {"torso": 3.0})),
        (weight: 1.0, cost: Position(part: "r_palm_center", target: Point((-0.3, 0.1, 0.0)))),
    ],
    text: r#"(sigma: 9)"#,
    solver: (algo: "xnes", sigma: -1.0),
)"##;

    #[test]
    fn paths_find_their_own_field_not_the_first_word_that_matches() {
        assert_eq!(locate_ron_path(SPEC, "solver.sigma"), Some((14, 28)));
        assert_eq!(locate_ron_path(SPEC, "noise.sigma"), Some((4, 30)));
        assert_eq!(locate_ron_path(SPEC, "world.objects[1].xyz"), Some((7, 52)));
        assert_eq!(locate_ron_path(SPEC, "world.objects[1]"), Some((7, 9)));
        assert_eq!(locate_ron_path(SPEC, "costs[1].cost.part"), Some((11, 38)));
        assert_eq!(
            locate_ron_path(SPEC, "costs[0].cost.weights.torso"),
            Some((10, 51))
        );
        assert_eq!(
            locate_ron_path(SPEC, "world.objects[1].shape.radius"),
            Some((7, 37))
        );
        assert_eq!(locate_ron_path(SPEC, "costs[2]"), None);
        assert_eq!(locate_ron_path(SPEC, "solver.seed"), None);
        assert_eq!(locate_ron_path(SPEC, ""), Some((2, 1)));
    }

    #[test]
    fn broken_or_hostile_text_gives_none_not_a_panic() {
        for text in [
            "",
            "(",
            "(a: ",
            "((((((",
            "(a: [1, 2",
            "\"unterminated",
            "r#\"x",
            "{1: }",
            "(a b)",
        ] {
            let _ = locate_ron_path(text, "a[0].b");
        }
        let deep = "(".repeat(100_000);
        assert_eq!(locate_ron_path(&deep, "a"), None);
    }

    #[test]
    fn a_delimiter_where_a_value_belongs_ends_the_walk() {
        // found by fuzzing (fuzz/artifacts/world/oom-57fb…): `(x: [1, :` once looped forever,
        // filling memory with empty nodes
        for text in ["(x: [1, :])", "(a: (1, }))", "[(nam: x back, ght\", 1)]"] {
            assert_eq!(locate_ron_path(text, "x[5]"), None, "{text}");
        }
        let found = include_str!("../tests/fixtures/fuzz_world_oom.ron");
        assert_eq!(locate_ron_path(found, "objects[3].name"), None);
    }
}
