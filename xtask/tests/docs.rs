//! The README and the book (`docs/`) keep their links: every relative link and image resolves
//! to a file of the repository (and its `#anchor` to a heading), every link to the repository's
//! own GitHub pages names a file that exists, every book page is in `SUMMARY.md`, every
//! `{{#include}}` finds its file, and the README stays a front door (≤ 200 lines).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The repository's pages on GitHub: links there must name files that exist here.
const REPO_URL: &str = "https://github.com/trm-robotics/trm/blob/main/";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The Markdown files whose links are checked.
fn pages() -> Vec<PathBuf> {
    let root = root();
    let mut pages = vec![root.join("README.md")];
    let mut dirs = vec![root.join("docs/src")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                pages.push(path);
            }
        }
    }
    for krate in std::fs::read_dir(root.join("crates")).unwrap() {
        let krate = krate.unwrap().path();
        pages.extend([krate.join("README.md")].into_iter().filter(|p| p.exists()));
        if let Ok(docs) = std::fs::read_dir(krate.join("docs")) {
            pages.extend(docs.map(|d| d.unwrap().path()));
        }
    }
    pages.sort();
    pages
}

/// The text outside fenced code blocks and inline code spans.
fn prose(text: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            out.push('\n');
            continue;
        }
        if fenced {
            out.push('\n');
            continue;
        }
        // drop inline code spans
        let mut inside = false;
        for c in line.chars() {
            if c == '`' {
                inside = !inside;
            } else if !inside {
                out.push(c);
            }
        }
        out.push('\n');
    }
    out
}

/// The targets of `[text](target)` and `![alt](target)` links, with their line numbers.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (n, line) in prose(text).lines().enumerate() {
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let end = after.find(')').unwrap_or(after.len());
            let target = after[..end].split_whitespace().next().unwrap_or("");
            found.push((n + 1, target.to_string()));
            rest = &after[end..];
        }
    }
    found
}

/// The anchors of a page's headings, as GitHub and mdBook make them.
fn anchors(text: &str) -> BTreeSet<String> {
    prose(text)
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| {
            l.trim_start_matches('#')
                .trim()
                .to_lowercase()
                .chars()
                .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
                .map(|c| if c == ' ' { '-' } else { c })
                .collect()
        })
        .collect()
}

/// What is wrong with `target` as linked from `page` (`None`: it resolves).
fn broken(page: &Path, target: &str) -> Option<String> {
    let (path, anchor) = match target.split_once('#') {
        Some((p, a)) => (p, Some(a)),
        None => (target, None),
    };
    let file = if let Some(inside) = path.strip_prefix(REPO_URL) {
        root().join(inside)
    } else if path.contains("://") || path.starts_with("mailto:") {
        return None;
    } else if path.is_empty() {
        page.to_path_buf()
    } else {
        page.parent().unwrap().join(path)
    };
    if !file.exists() {
        return Some(format!("{} does not exist", file.display()));
    }
    let anchor = anchor.filter(|a| !a.is_empty())?;
    if file.extension().is_some_and(|e| e == "md") {
        let text = std::fs::read_to_string(&file).unwrap();
        if !anchors(&text).contains(anchor) {
            return Some(format!("no heading #{anchor} in {}", file.display()));
        }
    }
    None
}

#[test]
fn every_link_of_the_readme_and_the_book_resolves() {
    let mut problems = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for (line, target) in links(&text) {
            if let Some(why) = broken(&page, &target) {
                problems.push(format!("{}:{line}: ({target}): {why}", page.display()));
            }
        }
        for (n, line) in text.lines().enumerate() {
            if let Some(rest) = line.trim().strip_prefix("{{#include ") {
                let target = rest.trim_end_matches("}}").trim();
                if !page.parent().unwrap().join(target).exists() {
                    problems.push(format!(
                        "{}:{}: include {target} not found",
                        page.display(),
                        n + 1
                    ));
                }
            }
        }
    }
    assert!(
        problems.is_empty(),
        "broken links:\n{}",
        problems.join("\n")
    );
}

#[test]
fn every_book_page_is_in_the_summary() {
    let src = root().join("docs/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let listed: BTreeSet<PathBuf> = links(&summary)
        .into_iter()
        .map(|(_, t)| src.join(t))
        .collect();
    let pages: Vec<PathBuf> = pages()
        .into_iter()
        .filter(|p| p.starts_with(&src) && !p.ends_with("SUMMARY.md"))
        .collect();
    let missing: Vec<_> = pages.iter().filter(|p| !listed.contains(*p)).collect();
    assert!(
        missing.is_empty(),
        "book pages missing from SUMMARY.md: {missing:?}"
    );
    for page in &listed {
        assert!(
            page.exists(),
            "SUMMARY.md lists {} which does not exist",
            page.display()
        );
    }
}

#[test]
fn the_readme_stays_a_front_door() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(
        lines <= 200,
        "README.md has {lines} lines: move the detail into the book (docs/)"
    );
}

#[test]
fn the_checker_finds_broken_links() {
    let page = root().join("README.md");
    assert!(broken(&page, "docs/src/nothing-here.md").is_some());
    assert!(broken(&page, "docs/src/SUMMARY.md").is_none());
    assert!(broken(&page, "#no-such-heading").is_some());
    assert!(broken(&page, "#two-commands").is_none());
    assert!(broken(&page, &format!("{REPO_URL}models/none.urdf")).is_some());
    assert_eq!(
        links("a [b](c.md) `[d](e)` ![f](g.svg)"),
        [(1, "c.md".into()), (1, "g.svg".into())]
    );
}
