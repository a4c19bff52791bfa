//! The hostile-input battery's harness: cases, the binary run with a hang guard, mechanical
//! mutations of valid files, and the run of a whole battery. Shared by trm's battery
//! (`crates/trm/tests/hostile`) and the study commands' (`xtask/tests/hostile_studies.rs`),
//! each of which uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// One run of the binary that must fail cleanly.
pub struct Case {
    /// What is wrong, for the report.
    pub what: String,
    /// The command line after the binary.
    pub args: Vec<String>,
    /// Text the error message must contain (the file or flag at fault).
    pub names: String,
}

/// The repository's root: the nearest folder above the test's crate holding `specs/`.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .find(|d| d.join("specs/reach.ron").is_file())
        .expect("the test runs inside the repository")
        .to_path_buf()
}

/// A command still running after this is taken for hung: far above any case's time on a
/// loaded 2-core machine, so that the verdict never depends on speed.
pub const HANG: Duration = Duration::from_secs(240);

/// Runs `bin` with `args` in `dir`: (exit code, stderr, seconds); killed after [`HANG`].
pub fn run(bin: &Path, dir: &Path, args: &[String]) -> (Option<i32>, String, f64) {
    let start = Instant::now();
    let mut child = Command::new(bin)
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .env("RUST_BACKTRACE", "0")
        .spawn()
        .expect("the binary starts");
    let stderr = child.stderr.take().expect("piped");
    let reader = std::thread::spawn(move || std::io::read_to_string(stderr).unwrap_or_default());
    let code = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status.code();
        }
        if start.elapsed() > HANG {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    (
        code,
        reader.join().unwrap_or_default(),
        start.elapsed().as_secs_f64(),
    )
}

/// For each byte of `text`, whether it is code: outside strings and `//` comments.
pub fn code(text: &str) -> Vec<bool> {
    let b = text.as_bytes();
    let mut mask = vec![true; b.len()];
    let mut i = 0;
    while i < b.len() {
        let start = i;
        match b[i] {
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            _ => {
                i += 1;
                continue;
            }
        }
        for m in &mut mask[start..i.min(b.len())] {
            *m = false;
        }
    }
    mask
}

/// Byte ranges of the number tokens of `text`, outside strings and `//` comments.
pub fn numbers(text: &str) -> Vec<(usize, usize)> {
    let (b, code) = (text.as_bytes(), code(text));
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let starts = code[i]
            && (c.is_ascii_digit() || c == b'-')
            && !(i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'))
            && (c != b'-' || b.get(i + 1).is_some_and(u8::is_ascii_digit));
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        i += 1;
        while i < b.len() && (b[i].is_ascii_digit() || b".eE+-".contains(&b[i])) {
            i += 1;
        }
        out.push((start, i));
    }
    out
}

/// At most `n` items of `items`, evenly spread.
pub fn spread<T: Clone>(items: &[T], n: usize) -> Vec<T> {
    if items.len() <= n {
        return items.to_vec();
    }
    (0..n).map(|k| items[k * items.len() / n].clone()).collect()
}

/// Mutations of a file's text: (what, new text).
pub fn mutations(
    text: &str,
    json: bool,
    per_value: usize,
    values: &[&str],
) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (s, e) in spread(&numbers(text), per_value) {
        for v in values {
            out.push((
                format!("{} → {v} at byte {s}", &text[s..e]),
                format!("{}{v}{}", &text[..s], &text[e..]),
            ));
        }
    }
    for k in [1, 3, 5, 7, 9] {
        // the char boundary at or before k tenths (`floor_char_boundary` needs Rust 1.91)
        let cut = (0..=text.len() * k / 10)
            .rev()
            .find(|&i| text.is_char_boundary(i))
            .unwrap_or(0);
        out.push((format!("truncated at byte {cut}"), text[..cut].to_string()));
    }
    let open = opening(text, if json { b'{' } else { b'(' });
    let unknown = if json {
        "\"no_such_key\": 1, "
    } else {
        "no_such_field: 1, "
    };
    out.push((
        "an unknown field".into(),
        format!("{}{unknown}{}", &text[..open], &text[open..]),
    ));
    // the first key again, with a value of another type
    if let Some(key) = first_key(&text[open..], json) {
        let dup = if json {
            format!("\"{key}\": \"twice\", ")
        } else {
            format!("{key}: \"twice\", ")
        };
        out.push((
            format!("`{key}` given twice"),
            format!("{}{dup}{}", &text[..open], &text[open..]),
        ));
    }
    // a numeric array one element short
    if let Some((s, e)) = numbers(text)
        .windows(2)
        .find(|w| text[w[0].1..w[1].0].trim() == ",")
        .map(|w| (w[0].1, w[1].1))
    {
        out.push((
            format!("an array without its element at byte {s}"),
            format!("{}{}", &text[..s], &text[e..]),
        ));
    }
    out
}

/// Just after the first `bracket` outside strings and `//` comments.
pub fn opening(text: &str, bracket: u8) -> usize {
    let code = code(text);
    (text.bytes().enumerate())
        .find(|&(i, c)| code[i] && c == bracket)
        .map_or(0, |(i, _)| i + 1)
}

/// Byte ranges of the numbers in the attribute values of an XML text (`xyz="0 0.1 0"`).
pub fn attribute_numbers(text: &str) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    // after the XML declaration (`<?xml version="1.0"?>`)
    let mut from = text.find("?>").map_or(0, |k| k + 2);
    while let Some(k) = text[from..].find("=\"") {
        let start = from + k + 2;
        let end = start + text[start..].find('"').unwrap_or(0);
        let value = &text[start..end];
        if let Some(n) = value.find(|c: char| c.is_ascii_digit() || c == '-') {
            let len = value[n..]
                .find(|c: char| !(c.is_ascii_digit() || ".eE+-".contains(c)))
                .unwrap_or(value.len() - n);
            out.push((start + n, start + n + len));
        }
        from = end + 1;
    }
    out
}

/// The first key (JSON) or field name (RON) after an opening bracket.
pub fn first_key(text: &str, json: bool) -> Option<String> {
    let t = text.trim_start();
    if json {
        let t = t.strip_prefix('"')?;
        Some(t[..t.find('"')?].to_string())
    } else {
        let end = t.find(|c: char| !(c.is_alphanumeric() || c == '_'))?;
        (end > 0 && t[end..].trim_start().starts_with(':')).then(|| t[..end].to_string())
    }
}

/// Writes each mutation of `source` to `dir` as `name_<k>.<ext>` and makes a case running
/// `args` with `{}` replaced by that file.
pub fn file_cases(
    dir: &Path,
    source: &Path,
    mutated: Vec<(String, String)>,
    args: &[&str],
) -> Vec<Case> {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let stem = source
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .replace('.', "_");
    let ext = source.extension().unwrap().to_string_lossy().to_string();
    mutated
        .into_iter()
        .map(|(what, text)| {
            let k = NEXT.fetch_add(1, Ordering::Relaxed);
            let name = format!("{stem}_{k}.{ext}");
            std::fs::write(dir.join(&name), text).unwrap();
            Case {
                what: format!("{}: {what}", source.display()),
                args: args.iter().map(|a| a.replace("{}", &name)).collect(),
                names: name,
            }
        })
        .collect()
}

/// Cases running `command` with `flag` set to each of `values`; the error must name the flag.
pub fn flag_cases(command: &[&str], flag: &str, values: &[&str]) -> Vec<Case> {
    let mut cases = file_flag_cases(command, flag, values);
    for c in &mut cases {
        c.names = flag.to_string();
    }
    cases
}

/// Cases running `command` with `flag` set to each of `values` (files); the error must name the
/// file.
pub fn file_flag_cases(command: &[&str], flag: &str, values: &[&str]) -> Vec<Case> {
    values
        .iter()
        .map(|v| Case {
            what: format!("{} {flag} {v}", command[0]),
            args: command
                .iter()
                .map(|s| s.to_string())
                .chain([flag.to_string(), v.to_string()])
                .collect(),
            names: v.to_string(),
        })
        .collect()
}

/// Makes the valid files the battery mutates: a 4-point map, a posture, trajectories.
/// The valid files the cases mutate, made in `dir` by `bin` (trm) or copied.
pub fn valid_files(bin: &Path, dir: &Path) {
    let root = root();
    let make = |args: &[&str]| {
        let (code, stderr, _) = run(
            bin,
            dir,
            &args.iter().map(|s| s.to_string()).collect::<Vec<_>>(),
        );
        assert_eq!(code, Some(0), "{args:?}: {stderr}");
    };
    let spec = root.join("specs/reach.ron");
    let spec = spec.to_str().unwrap();
    make(&["build-map", spec, "--points", "4", "--out", "map.json"]);
    make(&[
        "build-map",
        spec,
        "--points",
        "4",
        "--out",
        "ck.map.json",
        "--checkpoint-every",
        "2",
    ]);
    make(&["solve", spec, "--out", "posture.json"]);
    let map: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("map.json")).unwrap()).unwrap();
    let t = &map["points"][3]["t"];
    let to = format!("{},{},{}", t[0], t[1], t[2]);
    make(&[
        "plan", "--map", "map.json", "--to", &to, "--out", "traj.csv",
    ]);
    std::fs::write(dir.join("to.txt"), &to).unwrap();
    // the posture without its metadata (free-form, not checked): the motor values only
    let posture: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("posture.json")).unwrap()).unwrap();
    let motors = serde_json::json!({ "motors": posture["motors"] });
    std::fs::write(
        dir.join("posture.json"),
        serde_json::to_string_pretty(&motors).unwrap(),
    )
    .unwrap();
    for (from, to) in [
        ("specs/configs/icub_arms.json", "configs.json"),
        ("specs/worlds/reach_with_box.ron", "world.ron"),
        ("models/icub_upper_body.urdf", "icub_upper_body.urdf"),
        ("models/icub_upper_body.ron", "icub_upper_body.ron"),
    ] {
        std::fs::copy(root.join(from), dir.join(to)).unwrap();
    }
    // a joint_limits.yaml whose acceleration flag is on without a limit
    std::fs::write(
        dir.join("bad_limits.yaml"),
        "joint_limits:\n  panda_joint1:\n    has_acceleration_limits: true\n",
    )
    .unwrap();
}

/// Every path under `dir`.
pub fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if e.file_type().is_ok_and(|t| t.is_dir()) {
                stack.push(p.clone());
            }
            out.push(p);
        }
    }
    out.sort();
    out
}

/// Runs every case with `bin` in `dir`, two at a time: each must fail cleanly (exit code 1–100,
/// no panic, within [`HANG`], its error naming `names`), there must be at least `minimum`, and
/// the failed runs must leave nothing in `dir`, which is then removed.
pub fn run_all(bin: &Path, dir: &Path, cases: &[Case], minimum: usize) {
    let before: Vec<_> = listing(dir);
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    let slowest = Mutex::new((0.0f64, String::new()));
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                while let Some(case) = cases.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let (code, stderr, secs) = run(bin, dir, &case.args);
                    let mut slow = slowest.lock().unwrap();
                    if secs > slow.0 {
                        *slow = (secs, case.what.clone());
                    }
                    drop(slow);
                    let problem = match code {
                        None => Some(format!("no exit within {} s (or killed)", HANG.as_secs())),
                        Some(0) => Some("accepted".to_string()),
                        Some(c) if c > 100 => Some(format!("exit code {c}")),
                        _ if stderr.contains("panicked") => Some("panicked".into()),
                        _ if !stderr.contains(&case.names) => {
                            Some(format!("the error does not name `{}`", case.names))
                        }
                        _ => None,
                    };
                    if let Some(p) = problem {
                        failures.lock().unwrap().push(format!(
                            "{} ({}): {p}\n    {} {}\n    {}",
                            case.what,
                            case.names,
                            bin.display(),
                            case.args.join(" "),
                            stderr.trim().replace('\n', "\n    ")
                        ));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    let (secs, what) = slowest.into_inner().unwrap();
    eprintln!(
        "{} hostile inputs, {} without a clear error; slowest {secs:.1} s ({what})",
        cases.len(),
        failures.len()
    );
    assert!(cases.len() >= minimum, "only {} cases", cases.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // failed runs wrote nothing: the directory holds only the inputs
    let after = listing(dir);
    let new: Vec<_> = after.iter().filter(|p| !before.contains(p)).collect();
    assert!(new.is_empty(), "failed runs left files behind: {new:?}");
    let _ = std::fs::remove_dir_all(dir);
}

/// Each command given `path` as its last argument, where it wants an output (a file or a
/// folder) and `path` cannot be one (a regular file for a folder, a symlink, a device, a
/// directory, a path under a file): the error must name `path`.
pub fn output_cases(commands: &[Vec<&str>], path: &str) -> Vec<Case> {
    commands
        .iter()
        .map(|command| Case {
            what: format!("{} with {path} as its output", command[0]),
            args: command
                .iter()
                .map(|s| s.to_string())
                .chain([path.to_string()])
                .collect(),
            names: path.into(),
        })
        .collect()
}
