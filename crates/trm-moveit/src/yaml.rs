//! A YAML document as a small tree whose every node knows its line, read from yaml-rust2's
//! event stream without recursion and refused nested deeper than [`YAML_NESTING_LIMIT`], so
//! that errors name the line and no input can overflow the stack.

use yaml_rust2::parser::{Event, Parser};

/// The deepest nesting of mappings and sequences the YAML readers accept (MoveIt's messages
/// nest about 8 deep).
pub const YAML_NESTING_LIMIT: usize = 64;

/// A node of a YAML document.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A mapping, keys in document order.
    Map(Vec<(String, Node)>),
    /// A sequence.
    Seq(Vec<Node>),
    /// A scalar, as written.
    Scalar(String),
}

/// A value and the line (from 1) it starts on.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// The value.
    pub value: Value,
    /// Line, from 1.
    pub line: usize,
}

/// Where and why a YAML text could not be read.
#[derive(Debug, Clone, PartialEq)]
pub struct YamlProblem {
    /// Line, from 1.
    pub line: usize,
    /// What is wrong.
    pub problem: String,
}

enum Open {
    Map(Vec<(String, Node)>, Option<String>, usize),
    Seq(Vec<Node>, usize),
}

/// Parses the first document of `text` into a tree (an empty text is an empty mapping).
/// Anchors and aliases, non-string keys and duplicate keys are refused, as is nesting deeper
/// than [`YAML_NESTING_LIMIT`].
pub fn parse(text: &str) -> Result<Node, YamlProblem> {
    let mut parser = Parser::new_from_str(text);
    let mut stack: Vec<Open> = Vec::new();
    let mut root: Option<Node> = None;
    loop {
        let (event, mark) = parser.next_token().map_err(|e| YamlProblem {
            line: e.marker().line(),
            problem: e.info().to_string(),
        })?;
        let line = mark.line();
        let done = match event {
            Event::StreamEnd | Event::DocumentEnd => true,
            Event::Nothing | Event::StreamStart | Event::DocumentStart => false,
            Event::Alias(_) => {
                return Err(YamlProblem {
                    line,
                    problem: "aliases (`*name`) are not read".into(),
                });
            }
            Event::Scalar(s, ..) => {
                attach(&mut stack, &mut root, Value::Scalar(s), line)?;
                false
            }
            Event::SequenceStart(..) | Event::MappingStart(..) => {
                if stack.len() >= YAML_NESTING_LIMIT {
                    return Err(YamlProblem {
                        line,
                        problem: format!("nested more than {YAML_NESTING_LIMIT} deep"),
                    });
                }
                stack.push(match event {
                    Event::SequenceStart(..) => Open::Seq(Vec::new(), line),
                    _ => Open::Map(Vec::new(), None, line),
                });
                false
            }
            Event::SequenceEnd | Event::MappingEnd => {
                let (value, start) = match stack.pop() {
                    Some(Open::Seq(items, start)) => (Value::Seq(items), start),
                    Some(Open::Map(entries, _, start)) => (Value::Map(entries), start),
                    None => {
                        return Err(YamlProblem {
                            line,
                            problem: "a collection closes that never opened".into(),
                        });
                    }
                };
                attach(&mut stack, &mut root, value, start)?;
                false
            }
        };
        if done || (root.is_some() && stack.is_empty()) {
            break;
        }
    }
    Ok(root.unwrap_or(Node {
        value: Value::Map(Vec::new()),
        line: 1,
    }))
}

/// Puts a finished value into the node being built (as a key, a value or an item), or makes it
/// the root.
fn attach(
    stack: &mut [Open],
    root: &mut Option<Node>,
    value: Value,
    line: usize,
) -> Result<(), YamlProblem> {
    let node = Node { value, line };
    match stack.last_mut() {
        None => *root = Some(node),
        Some(Open::Seq(items, _)) => items.push(node),
        Some(Open::Map(entries, key, _)) => match key.take() {
            Some(k) => entries.push((k, node)),
            None => {
                let Value::Scalar(k) = node.value else {
                    return Err(YamlProblem {
                        line,
                        problem: "a key that is not a plain string".into(),
                    });
                };
                if entries.iter().any(|(e, _)| *e == k) {
                    return Err(YamlProblem {
                        line,
                        problem: format!("`{k}` is given twice"),
                    });
                }
                *key = Some(k);
            }
        },
    }
    Ok(())
}

impl Node {
    /// The entry `key` of a mapping.
    pub fn get(&self, key: &str) -> Option<&Node> {
        match &self.value {
            Value::Map(entries) => entries.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// The items of a sequence.
    pub fn items(&self) -> Option<&[Node]> {
        match &self.value {
            Value::Seq(items) => Some(items),
            _ => None,
        }
    }

    /// A scalar's text.
    pub fn scalar(&self) -> Option<&str> {
        match &self.value {
            Value::Scalar(s) => Some(s),
            _ => None,
        }
    }

    /// What kind of node this is, for error messages.
    pub fn kind(&self) -> &'static str {
        match &self.value {
            Value::Map(_) => "a mapping",
            Value::Seq(_) => "a sequence",
            Value::Scalar(_) => "a scalar",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mappings_sequences_and_scalars_keep_their_lines() {
        let doc = parse("a: 1\nb:\n  - [x, y]\n  - {c: 2}\n").unwrap();
        assert_eq!(doc.get("a").unwrap().scalar(), Some("1"));
        let b = doc.get("b").unwrap().items().unwrap();
        assert_eq!(b[0].line, 3);
        assert_eq!(b[0].items().unwrap()[1].scalar(), Some("y"));
        assert_eq!(b[1].get("c").unwrap().line, 4);
    }

    #[test]
    fn duplicate_keys_aliases_and_deep_nesting_are_refused_with_their_lines() {
        assert_eq!(parse("a: 1\na: 2\n").unwrap_err().line, 2);
        assert!(
            parse("a: &x 1\nb: *x\n")
                .unwrap_err()
                .problem
                .contains("aliases")
        );
        let deep = "- ".repeat(100_000) + "x\n";
        let e = parse(&deep).unwrap_err();
        assert!(e.problem.contains("nested more than 64 deep"), "{e:?}");
        let flow = "[".repeat(200) + &"]".repeat(200);
        assert!(parse(&flow).is_err());
        assert!(parse("a: [1, 2\n").is_err());
        assert_eq!(parse("").unwrap().value, Value::Map(Vec::new()));
    }
}
