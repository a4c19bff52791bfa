//! The hostile-input battery: several hundred malformed files, flag values and output paths
//! across the commands, each run through the `xtask` binary. Every one must end in a clear
//! error: exit code 1–100, no panic, no hang (240 s, far above any case's time on a loaded
//! machine), naming the file (or flag) at fault, and writing nothing.
//!
//! Files are mutated mechanically from valid ones (specs/, models/, and a map, posture and
//! trajectory this test makes): every number of a file (or an even sample of them) replaced by a
//! non-finite or out-of-range value, truncations, duplicated and unknown keys, wrong types,
//! numeric arrays one element short.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// One run of the binary that must fail cleanly.
struct Case {
    /// What is wrong, for the report.
    what: String,
    /// The command line after `xtask`.
    args: Vec<String>,
    /// Text the error message must contain (the file or flag at fault).
    names: String,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A command still running after this is taken for hung: far above any case's time on a
/// loaded 2-core machine, so that the verdict never depends on speed.
const HANG: Duration = Duration::from_secs(240);

/// Runs the binary with `args` in `dir`: (exit code, stderr, seconds); killed after [`HANG`].
fn run(dir: &Path, args: &[String]) -> (Option<i32>, String, f64) {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .env("RUST_BACKTRACE", "0")
        .spawn()
        .expect("xtask starts");
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
fn code(text: &str) -> Vec<bool> {
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
fn numbers(text: &str) -> Vec<(usize, usize)> {
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
fn spread<T: Clone>(items: &[T], n: usize) -> Vec<T> {
    if items.len() <= n {
        return items.to_vec();
    }
    (0..n).map(|k| items[k * items.len() / n].clone()).collect()
}

/// Mutations of a file's text: (what, new text).
fn mutations(text: &str, json: bool, per_value: usize, values: &[&str]) -> Vec<(String, String)> {
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
        let cut = text.floor_char_boundary(text.len() * k / 10);
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
fn opening(text: &str, bracket: u8) -> usize {
    let code = code(text);
    (text.bytes().enumerate())
        .find(|&(i, c)| code[i] && c == bracket)
        .map_or(0, |(i, _)| i + 1)
}

/// Byte ranges of the numbers in the attribute values of an XML text (`xyz="0 0.1 0"`).
fn attribute_numbers(text: &str) -> Vec<(usize, usize)> {
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
fn first_key(text: &str, json: bool) -> Option<String> {
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
fn file_cases(
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
fn flag_cases(command: &[&str], flag: &str, values: &[&str]) -> Vec<Case> {
    let mut cases = file_flag_cases(command, flag, values);
    for c in &mut cases {
        c.names = flag.to_string();
    }
    cases
}

/// Cases running `command` with `flag` set to each of `values` (files); the error must name the
/// file.
fn file_flag_cases(command: &[&str], flag: &str, values: &[&str]) -> Vec<Case> {
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
fn valid_files(dir: &Path) {
    let root = root();
    let make = |args: &[&str]| {
        let (code, stderr, _) = run(dir, &args.iter().map(|s| s.to_string()).collect::<Vec<_>>());
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

#[test]
fn hostile_inputs_get_clear_errors_and_write_nothing() {
    let dir = std::env::temp_dir().join(format!("trm-hostile-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    valid_files(&dir);
    let root = root();
    let read = |p: &Path| std::fs::read_to_string(p).unwrap();
    let at = |p: &str| root.join(p);
    let non_finite = ["NaN", "inf", "-inf"];
    let mut cases = Vec::new();

    // RON files, each through a command that reads it
    let stick_spec = at("specs/taskmaps/stick.ron").to_string_lossy().to_string();
    for (source, args) in [
        (
            at("specs/reach.ron"),
            vec!["solve", "{}", "--out", "o.json"],
        ),
        (at("specs/fig6/c_bimanual_grab.ron"), vec!["solve", "{}"]),
        (at("specs/table_iii/posture1.ron"), vec!["solve", "{}"]),
        (
            dir.join("world.ron"),
            vec!["collide", "--configs", "configs.json", "--world", "{}"],
        ),
        (
            at("specs/wholebody/standup.ron"),
            vec!["stand-up", "{}", "--out", "standup"],
        ),
        (
            at("specs/taskmaps/stick.ron"),
            vec!["explore-task-map", "{}", "--out", "o.taskmap.json"],
        ),
        (
            dir.join("world.ron"),
            vec![
                "reach-grasp",
                stick_spec.as_str(),
                "--iterations",
                "1",
                "--world",
                "{}",
            ],
        ),
        (
            at("specs/scenarios/sliding_box.ron"),
            vec!["scenario", "{}", "--map", "map.json", "--out-dir", "sc"],
        ),
    ] {
        let text = read(&source);
        cases.extend(file_cases(
            &dir,
            &source,
            mutations(&text, false, 12, &non_finite),
            &args,
        ));
    }
    // values that parse but make no sense: zero or huge counts, inverted or degenerate ranges,
    // duplicated names
    let solve = ["solve", "{}"];
    let stand = ["stand-up", "{}", "--out", "su"];
    let collide = ["collide", "--configs", "configs.json", "--world", "{}"];
    let explore = ["explore-task-map", "{}"];
    let scenario = ["scenario", "{}", "--map", "map.json", "--out-dir", "sc"];
    let sliding = "specs/scenarios/sliding_box.ron";
    for (source, from, to, args) in [
        (
            "specs/reach.ron",
            "max_points: 400",
            "max_points: 0",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "max_points: 400",
            "max_points: 99999999999",
            &solve[..],
        ),
        ("specs/reach.ron", "searches: 4", "searches: 0", &solve[..]),
        (
            "specs/reach.ron",
            "(150, 0.15)",
            "(10000000000000, 0.15)",
            &solve[..],
        ),
        ("specs/reach.ron", "(30, 0.03)", "(30, -0.03)", &solve[..]),
        (
            "specs/reach.ron",
            "seed: 0)",
            "seed: 0, population: Some(10000000000000))",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "seed: 0)",
            "seed: 0, max_evaluations: 0)",
            &solve[..],
        ),
        ("specs/reach.ron", "weight: 5.0", "weight: -5.0", &solve[..]),
        (
            "specs/reach.ron",
            "radius: 0.05",
            "radius: -0.05",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "axis: (0, 1, 0)",
            "axis: (0, 0, 0)",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "\"l_palm_center\"",
            "\"l_palm_centre\"",
            &solve[..],
        ),
        ("specs/reach.ron", "\"xnes\"", "\"xnse\"", &solve[..]),
        (
            "specs/reach.ron",
            "\"torso\": 3.0",
            "\"torso\": 3.0, \"torso\": 1.0",
            &solve[..],
        ),
        (
            "specs/reach.ron",
            "size: (0.5, 0.8, 0.04)",
            "size: (0.5, 0.0, 0.04)",
            &solve[..],
        ),
        (
            "specs/worlds/reach_with_box.ron",
            "\"new_box\"",
            "\"table\"",
            &collide[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "dt: 0.01",
            "dt: 1e-300",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "dt: 0.01",
            "dt: 0.00001",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "rbfs: 5",
            "rbfs: 0",
            &stand[..],
        ),
        (
            "specs/worlds/reach_with_box.ron",
            "\"new_box\"",
            "\"\"",
            &collide[..],
        ),
        (
            "specs/worlds/reach_with_box.ron",
            "\"new_box\"",
            "\"  \"",
            &collide[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "rbfs: 5",
            "rbfs: 100000000",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "\"standing\"",
            "\"seated\"",
            &stand[..],
        ),
        (
            "specs/wholebody/standup.ron",
            "end: 4.5",
            "end: 1.0",
            &stand[..],
        ),
        (
            "specs/taskmaps/stick.ron",
            "samples: 5000",
            "samples: 0",
            &explore[..],
        ),
        (sliding, "duration: 6.0", "duration: 0.0", &scenario[..]),
        (sliding, "rate: 10.0", "rate: 1e9", &scenario[..]),
        (sliding, "rate: 10.0", "rate: -10.0", &scenario[..]),
        (
            sliding,
            "to: [-0.3, 0.15, 0.1]",
            "to: [-0.3, 0.15]",
            &scenario[..],
        ),
        (sliding, "to: [-0.3, 0.15, 0.1]", "to: []", &scenario[..]),
        (sliding, "(t: 1.5, to:", "(t: -1.5, to:", &scenario[..]),
        (sliding, "(t: 2.5, xyz:", "(t: 7.5, xyz:", &scenario[..]),
        (sliding, "name: \"can\"", "name: \"table\"", &scenario[..]),
        (
            sliding,
            "name: \"can\"",
            "name: \"sliding_box\"",
            &scenario[..],
        ),
        (
            sliding,
            "appear: 2.0",
            "appear: 2.0, vanish: Some(1.0)",
            &scenario[..],
        ),
        (sliding, "radius: 0.03", "radius: 0.0", &scenario[..]),
        (sliding, "goals: [", "goals: [], goal: [", &scenario[..]),
        (sliding, "duration: 6.0,", "", &scenario[..]),
    ] {
        let text = read(&at(source));
        assert!(text.contains(from), "{source} has no `{from}`");
        cases.extend(file_cases(
            &dir,
            &at(source),
            vec![(format!("`{from}` → `{to}`"), text.replacen(from, to, 1))],
            args,
        ));
    }

    // the model description (next to its URDF) and the URDF
    let text = read(&dir.join("icub_upper_body.ron"));
    cases.extend(file_cases(
        &dir,
        &dir.join("icub_upper_body.ron"),
        mutations(&text, false, 10, &non_finite),
        &["model-info", "{}"],
    ));
    let urdf = read(&dir.join("icub_upper_body.urdf"));
    let mut bad_urdf: Vec<(String, String)> = spread(&attribute_numbers(&urdf), 30)
        .into_iter()
        .map(|(s, e)| {
            (
                format!("{} → nan at byte {s}", &urdf[s..e]),
                format!("{}nan{}", &urdf[..s], &urdf[e..]),
            )
        })
        .collect();
    for k in [1, 5, 9] {
        let cut = urdf.len() * k / 10;
        bad_urdf.push((format!("truncated at byte {cut}"), urdf[..cut].to_string()));
    }
    bad_urdf.push((
        "a joint named twice".into(),
        urdf.replacen("name=\"r_elbow\"", "name=\"r_shoulder_pitch\"", 1),
    ));
    bad_urdf.push((
        "a parent link that does not exist".into(),
        urdf.replacen("<parent link=\"", "<parent link=\"no_such_", 1),
    ));
    // found by fuzzing: urdf-rs's XML layer panics on this one
    bad_urdf.push((
        "an unbound namespace".into(),
        String::from_utf8_lossy(include_bytes!(
            "../../crates/trm-kinematics/tests/fixtures/fuzz_urdf_namespace.urdf"
        ))
        .into_owned(),
    ));
    cases.extend(file_cases(
        &dir,
        &dir.join("icub_upper_body.urdf"),
        bad_urdf,
        &["model-info", "{}"],
    ));

    // JSON and CSV files
    let huge = ["1e999", "null", "\"x\""];
    let to = read(&dir.join("to.txt"));
    let to = to.as_str();
    for (name, args, values, per_value) in [
        ("map.json", vec!["map-info", "{}"], &huge[..], 12),
        (
            "map.json",
            vec!["plan", "--map", "{}", "--to", "0,0,0", "--tolerance", "9"],
            &["1e999", "99"][..],
            12,
        ),
        (
            "posture.json",
            vec!["plan", "--map", "map.json", "--from", "{}", "--to", to],
            &["1e999", "99", "\"x\""][..],
            12,
        ),
        (
            "configs.json",
            vec!["fk", "--configs", "{}"],
            &["1e999", "99"][..],
            12,
        ),
        ("traj.json", vec!["view", "--traj", "{}"], &huge[..], 12),
    ] {
        let source = dir.join(name);
        let text = read(&source);
        let mut file = file_cases(
            &dir,
            &source,
            mutations(&text, true, per_value, values)
                .into_iter()
                // a posture file's other keys are its free-form metadata (documented)
                .filter(|(what, _)| !(name == "posture.json" && what == "an unknown field"))
                .collect(),
            &args,
        );
        cases.append(&mut file);
    }
    let csv = read(&dir.join("traj.csv"));
    let row = csv.lines().nth(1).unwrap();
    let mut bad_csv = vec![
        ("no header".to_string(), String::new()),
        (
            "a NaN".into(),
            csv.replacen(row, &row.replacen(",", ",NaN,", 1), 1),
        ),
        ("a value outside its limits".into(), {
            let mut fields: Vec<&str> = row.split(',').collect();
            fields[1] = "99";
            csv.replacen(row, &fields.join(","), 1)
        }),
        ("a row too short".into(), csv.replacen(row, "0", 1)),
        (
            "a header and no rows".into(),
            csv.lines().next().unwrap().to_string() + "\n",
        ),
        (
            "a negative time".into(),
            csv.replacen(row, &format!("-1{}", &row[1..]), 1),
        ),
        (
            "an unknown column".into(),
            csv.replacen("time,", "time,r_elbw,", 1),
        ),
    ];
    for k in [1, 5] {
        let cut = csv.len() * k / 10;
        bad_csv.push((format!("truncated at byte {cut}"), csv[..cut].to_string()));
    }
    cases.extend(file_cases(
        &dir,
        &dir.join("traj.csv"),
        bad_csv,
        &["view", "--traj", "{}"],
    ));

    // flag values
    let spec = at("specs/reach.ron").to_string_lossy().to_string();
    let spec = spec.as_str();
    let counts = ["0", "-1", "x", "1e3", "18446744073709551616"];
    cases.extend(flag_cases(&["build-map", spec], "--points", &counts));
    cases.extend(flag_cases(&["build-map", spec], "--points", &["100000000"]));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--searches",
        &["0", "5000", "-2"],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--threads",
        &["0", "-1", "x"],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--seed",
        &["-1", "x", "1.5"],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--edge-resolution",
        &["0", "-0.1", "NaN", "inf", "1e-300", "x"],
    ));
    // checkpoints: damaged, foreign, missing; flags that do not go with --resume
    let checkpoint = std::fs::read(dir.join("ck.map.checkpoint")).unwrap();
    let n = checkpoint.len();
    let mut damaged: Vec<(String, Vec<u8>)> = vec![("empty".into(), vec![])];
    for cut in [1, 10, n / 2, n - 1] {
        damaged.push((format!("cut at byte {cut}"), checkpoint[..cut].to_vec()));
    }
    for at in [0, 20, n / 3, 2 * n / 3, n - 1] {
        let mut bytes = checkpoint.clone();
        bytes[at] ^= 0x40;
        damaged.push((format!("byte {at} changed"), bytes));
    }
    damaged.push((
        "a map file".into(),
        std::fs::read(dir.join("map.json")).unwrap(),
    ));
    for (k, (what, bytes)) in damaged.into_iter().enumerate() {
        let name = format!("bad_{k}.checkpoint");
        std::fs::write(dir.join(&name), bytes).unwrap();
        cases.push(Case {
            what: format!("checkpoint: {what}"),
            args: ["build-map", "--resume", &name, "--out", "o.json"]
                .map(String::from)
                .to_vec(),
            names: name,
        });
    }
    cases.extend(file_flag_cases(
        &["build-map", "--out", "o.json"],
        "--resume",
        &["no_such.checkpoint", "."],
    ));
    cases.extend(flag_cases(
        &["build-map", spec],
        "--checkpoint-every",
        &["0", "-1", "x", "100000000"],
    ));
    let resume = [
        "build-map",
        "--resume",
        "ck.map.checkpoint",
        "--out",
        "o.json",
    ];
    cases.extend(flag_cases(&resume, "--seed", &["3"]));
    // the checkpoint holds 2 points (of 4): a resumed build does not shrink the map
    cases.push(Case {
        what: "build-map --resume with --points below the checkpoint's".into(),
        args: [
            "build-map",
            "--resume",
            "ck.map.checkpoint",
            "--points",
            "1",
            "--out",
            "o.json",
        ]
        .map(String::from)
        .to_vec(),
        names: "--points".into(),
    });
    cases.extend(flag_cases(&resume, "--searches", &["2"]));
    cases.push(Case {
        what: "build-map with a spec and --resume".into(),
        args: ["build-map", spec, "--resume", "ck.map.checkpoint"]
            .map(String::from)
            .to_vec(),
        names: "--resume".into(),
    });
    cases.push(Case {
        what: "build-map --mpi from an xtask built without MPI".into(),
        args: ["build-map", spec, "--points", "2", "--mpi"]
            .map(String::from)
            .to_vec(),
        names: "--features mpi".into(),
    });
    cases.push(Case {
        what: "build-map --checkpoint without an interval".into(),
        args: ["build-map", spec, "--checkpoint", "c.checkpoint"]
            .map(String::from)
            .to_vec(),
        names: "--checkpoint-every".into(),
    });
    // maps whose edge step or recorded world does not hold
    let map: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("map.json")).unwrap()).unwrap();
    let bad_maps = [
        ("edge_resolution", serde_json::json!(0.0)),
        ("edge_resolution", serde_json::json!(1e-300)),
        ("edge_resolution", serde_json::json!(-0.05)),
        (
            "world",
            serde_json::json!({"objects": [{"name": "ball", "shape": {"Sphere": {"radius": -1.0}}}]}),
        ),
        (
            "world",
            serde_json::json!({"objects": [
                {"name": "ball", "shape": {"Sphere": {"radius": 0.1}}},
                {"name": "ball", "shape": {"Sphere": {"radius": 0.1}}}]}),
        ),
        ("world", serde_json::json!("table")),
        (
            "parked",
            serde_json::json!({"points": [{"q": [0.0], "t": [0.0, 0.0, 0.0], "cost": 0.0}], "edges": []}),
        ),
        (
            "parked",
            serde_json::json!({"points": [], "edges": [[0, 99, 1.0]]}),
        ),
        (
            "parked",
            serde_json::json!({"points": [map["points"][0]], "edges": [[4, 4, 1.0]]}),
        ),
        ("parked", {
            // a parked point whose task vector is not its posture's
            let mut p = map["points"][0].clone();
            p["t"][0] = serde_json::json!(5.0);
            serde_json::json!({"points": [p], "edges": []})
        }),
        ("parked", serde_json::json!({"points": []})),
        ("edges", serde_json::json!([[0, 1, -0.5]])),
        ("settings", {
            let mut settings = map["settings"].clone();
            settings["spacing"] = serde_json::json!(-0.025);
            settings
        }),
        ("settings", {
            let mut settings = map["settings"].clone();
            settings["edge_neighbours"] = serde_json::json!(0);
            settings
        }),
    ];
    for (k, (key, value)) in bad_maps.into_iter().enumerate() {
        let mut bad = map.clone();
        bad[key] = value.clone();
        let name = format!("bad_map_{k}.map.json");
        std::fs::write(dir.join(&name), serde_json::to_string(&bad).unwrap()).unwrap();
        for command in [
            vec!["map-info", name.as_str()],
            vec![
                "repair-map",
                name.as_str(),
                "--world",
                "world.ron",
                "--out",
                "r.json",
            ],
        ] {
            cases.push(Case {
                what: format!("{} with {key} = {value}", command[0]),
                args: command.iter().map(|a| a.to_string()).collect(),
                names: name.clone(),
            });
        }
    }
    let sliding = at("specs/scenarios/sliding_box.ron");
    let sliding = sliding.to_str().unwrap();
    let run_scenario = ["scenario", sliding, "--map", "map.json", "--out-dir", "sc"];
    cases.extend(flag_cases(
        &run_scenario,
        "--repair-ms",
        &["0", "-1", "NaN", "inf", "x"],
    ));
    cases.extend(flag_cases(
        &run_scenario,
        "--repair-evaluations",
        &["0", "-1", "x"],
    ));
    cases.extend(flag_cases(&run_scenario, "--threads", &["0", "x"]));
    // MotionBenchMaker sets: missing, empty, not an archive, an unknown family, a broken scene
    let mbm = at("crates/trm-mbm/tests/fixtures/mbm")
        .to_string_lossy()
        .to_string();
    let panda = at("models/panda-mbm/panda.ron")
        .to_string_lossy()
        .to_string();
    let bench = |set: &str| -> Vec<String> {
        [
            "benchmark-mbm",
            set,
            "--model",
            panda.as_str(),
            "--out-dir",
            "mbm-out",
        ]
        .map(String::from)
        .to_vec()
    };
    std::fs::create_dir_all(dir.join("empty_set/family")).unwrap();
    std::fs::create_dir_all(dir.join("broken_set/box")).unwrap();
    std::fs::write(dir.join("broken_set/box/scene0001.yaml"), "world:\n  collision_objects:\n    - id: a\n      primitives: [{type: cone, dimensions: [1, 1]}]\n      primitive_poses: [{position: [0, 0, 0]}]\n").unwrap();
    std::fs::copy(
        at("crates/trm-mbm/tests/fixtures/mbm/box_panda/request0001.yaml"),
        dir.join("broken_set/box/request0001.yaml"),
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("lonely_set/box")).unwrap();
    std::fs::write(dir.join("lonely_set/box/scene0001.yaml"), "{}\n").unwrap();
    for (set, names) in [
        ("no_such_set", "no_such_set"),
        ("empty_set", "empty_set"),
        ("map.json", "map.json"),
        ("broken_set", "scene0001.yaml:4"),
        ("lonely_set", "request0001.yaml"),
    ] {
        cases.push(Case {
            what: format!("benchmark-mbm {set}"),
            args: bench(set),
            names: names.into(),
        });
    }
    for (flag, values) in [
        ("--per-family", &["0", "-1", "x"][..]),
        ("--max-seconds", &["0", "-1", "NaN", "inf"][..]),
        ("--resolution", &["0", "-0.1", "NaN", "1e-300"][..]),
        ("--max-iterations", &["0", "1e12"][..]),
        ("--seed", &["-1", "1.5"][..]),
        ("--ompl", &["0", "-1", "NaN"][..]),
        ("--sampler", &["sobol", ""][..]),
    ] {
        let names = if flag == "--resolution" {
            "resolution"
        } else {
            flag
        };
        for v in values {
            let mut args = bench(&mbm);
            args.extend([flag.to_string(), v.to_string()]);
            cases.push(Case {
                what: format!("benchmark-mbm {flag} {v}"),
                args,
                names: names.into(),
            });
        }
    }
    for out in ["map.json", "link_to_dir"] {
        let mut args = bench(&mbm);
        args.truncate(4);
        args.extend(["--out-dir".into(), out.into()]);
        cases.push(Case {
            what: format!("benchmark-mbm --out-dir {out}"),
            args,
            names: out.into(),
        });
    }
    let _ = std::os::unix::fs::symlink(dir.join("map.json"), dir.join("link_to_dir"));
    let mut both = bench(&mbm);
    both.extend(["--families".into(), "box_panda".into()]);
    cases.push(Case {
        what: "benchmark-mbm --ompl with --families".into(),
        args: both
            .into_iter()
            .chain(["--ompl".into(), "1".into()])
            .collect(),
        names: "--ompl".into(),
    });
    // VAMP beside trm: a program that is not there, not a program, or prints nonsense
    let fake = dir.join("fake_vamp.sh");
    std::fs::write(
        &fake,
        "#!/bin/sh\ncat > /dev/null\necho 'result box_panda 1 1 1 NaN 0 0 0 0 0'\n",
    )
    .unwrap();
    std::fs::set_permissions(&fake, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    for program in ["no/such/program", "map.json", "fake_vamp.sh"] {
        let mut args = bench(&mbm);
        args.extend(["--per-family", "1", "--vamp", program].map(String::from));
        cases.push(Case {
            what: format!("benchmark-mbm --vamp {program}"),
            args,
            names: "--vamp".into(),
        });
    }
    let mut robot_alone = bench(&mbm);
    robot_alone.extend(["--vamp-robot".into(), "ur5".into()]);
    cases.push(Case {
        what: "benchmark-mbm --vamp-robot without --vamp".into(),
        args: robot_alone,
        names: "--vamp".into(),
    });
    // task-space goals: an unknown link, tolerances without --task-space, with experience
    for (extra, names) in [
        (vec!["--task-space", "panda_hnd"], "panda_hand"),
        (vec!["--position-tolerance", "0.02"], "--task-space"),
        (
            vec!["--task-space", "panda_hand", "--experience"],
            "--experience",
        ),
        (
            vec!["--task-space", "panda_hand", "--orientation-tolerance", "0"],
            "--orientation-tolerance",
        ),
    ] {
        let mut args = bench(&mbm);
        args.extend(extra.iter().map(|s| s.to_string()));
        cases.push(Case {
            what: format!("benchmark-mbm {}", extra.join(" ")),
            args,
            names: names.into(),
        });
    }
    // maps attached: missing, not a map, a map of other motors (the iCub's)
    let bench_args = bench(&mbm);
    let bench_refs: Vec<&str> = bench_args.iter().map(String::as_str).collect();
    cases.extend(file_flag_cases(
        &bench_refs,
        "--map",
        &["no_such.json", "posture.json", "map.json"],
    ));
    let request = at("crates/trm-mbm/tests/fixtures/mbm/box_panda/request0001.yaml")
        .to_string_lossy()
        .to_string();
    let plan_request = [
        "plan",
        "--model",
        panda.as_str(),
        "--request",
        request.as_str(),
    ];
    cases.extend(file_flag_cases(
        &plan_request,
        "--with-map",
        &["no_such.json", "posture.json", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &plan_request,
        "--experience",
        &["posture.json", "map.json"],
    ));
    // timing: limits and factors out of range, joint-limit files that are none or wrong
    for (flag, values) in [
        ("--velocity-scaling", &["0", "1.5", "NaN"][..]),
        ("--acceleration-scaling", &["-1", "2"][..]),
        ("--max-deviation", &["-0.1", "inf"][..]),
        ("--sample-period", &["0", "NaN"][..]),
        ("--acceleration", &["0", "-2"][..]),
        ("--jerk", &["0", "NaN"][..]),
    ] {
        cases.extend(flag_cases(&plan_request, flag, values));
    }
    cases.extend(file_flag_cases(
        &plan_request,
        "--joint-limits",
        &["no_such.yaml", "posture.json", "bad_limits.yaml"],
    ));
    let mut families = bench(&mbm);
    families.extend(["--families".into(), "box_pand".into()]);
    cases.push(Case {
        what: "benchmark-mbm with an unknown family".into(),
        args: families,
        names: "box_panda".into(),
    });
    // gen-mbm: settings out of range, a spec that does not reach, outputs that are files
    let gen_spec = at("specs/mbm/icub_reach.ron").to_string_lossy().to_string();
    let gen_mbm = [
        "gen-mbm",
        gen_spec.as_str(),
        "--out",
        "gen-out",
        "--per-family",
        "1",
    ];
    for (flag, values) in [
        ("--per-family", &["0", "-1"][..]),
        ("--center", &["1,2", "1,2,NaN"][..]),
        ("--facing", &["0,0", "1"][..]),
        ("--tolerance", &["0", "-1", "NaN"][..]),
        ("--tries", &["0"][..]),
    ] {
        cases.extend(flag_cases(&gen_mbm, flag, values));
    }
    cases.push(Case {
        what: "gen-mbm with an unknown family".into(),
        args: gen_mbm
            .iter()
            .map(|s| s.to_string())
            .chain(["--families".into(), "kitchen".into()])
            .collect(),
        names: "kitchen".into(),
    });
    cases.push(Case {
        what: "gen-mbm with scenes out of reach".into(),
        args: gen_mbm
            .iter()
            .map(|s| s.to_string())
            .chain(["--center=-5,0,0".into(), "--tries".into(), "1".into()])
            .collect(),
        names: "center".into(),
    });
    cases.extend(file_flag_cases(
        &["gen-mbm", gen_spec.as_str(), "--per-family", "1"],
        "--out",
        &["map.json"],
    ));
    cases.push(Case {
        what: "gen-mbm with a spec that is not there".into(),
        args: ["gen-mbm", "no_such_spec.ron", "--out", "gen-out"]
            .map(String::from)
            .to_vec(),
        names: "no_such_spec.ron".into(),
    });
    // one budget or the other, not both
    let both: Vec<&str> = run_scenario
        .iter()
        .copied()
        .chain(["--repair-ms", "10"])
        .collect();
    cases.extend(flag_cases(&both, "--repair-evaluations", &["100"]));
    // a package path that is not there
    cases.extend(file_flag_cases(
        &["model-info", "icub_upper_body.urdf"],
        "--package-path",
        &["no/such/dir", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &["scenario", sliding, "--out-dir", "sc"],
        "--map",
        &["no_such.json", ".", "posture.json", "world.ron"],
    ));
    cases.extend(file_flag_cases(
        &["scenario", sliding, "--map", "map.json"],
        "--out-dir",
        &["posture.json"],
    ));
    for bad in ["no_such.ron", ".", "map.json", "world.ron"] {
        cases.push(Case {
            what: format!("scenario {bad}"),
            args: ["scenario", bad, "--map", "map.json", "--out-dir", "sc"]
                .map(String::from)
                .to_vec(),
            names: bad.into(),
        });
    }
    // SRDF files: malformed, unknown names, missing attributes, wrong values
    for (k, (what, text, names)) in [
        ("truncated XML", "<robot name=\"r\">\n  <group name=\"a\">", "srdf_0.srdf"),
        ("an unknown joint", "<robot name=\"icub_upper_body\">\n<group name=\"a\"><joint name=\"r_elbw\"/></group>\n</robot>", "r_elbow"),
        ("an unknown link in a group", "<robot name=\"icub_upper_body\">\n<group name=\"a\"><link name=\"r_hnd\"/></group>\n</robot>", "r_hand"),
        ("a missing attribute", "<robot name=\"icub_upper_body\">\n<end_effector name=\"e\" group=\"a\"/>\n</robot>", "parent_link"),
        ("a non-number", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"a\"><joint name=\"r_elbow\" value=\"x\"/></group_state></robot>", "srdf_4.srdf"),
        ("another root", "<urdf/>", "srdf_5.srdf"),
        ("a reversed chain", "<robot name=\"icub_upper_body\"><group name=\"a\"><chain base_link=\"r_hand\" tip_link=\"chest\"/></group></robot>", "srdf_6.srdf"),
        ("binary", "\u{0}\u{1}\u{2}", "srdf_7.srdf"),
        ("several values for a URDF joint", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"a\"><joint name=\"r_elbow\" value=\"0.1 0.2\"/></group_state></robot>", "r_elbow"),
        ("a NaN among a floating base's values", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group><group_state name=\"s\" group=\"a\"><joint name=\"root_joint\" value=\"0 0 NaN 0 0 0 1\"/></group_state></robot>", "srdf_9.srdf"),
        ("a robot name other than the URDF's", "<robot name=\"panda\">\n</robot>", "icub_upper_body"),
        ("a group defined twice", "<robot name=\"icub_upper_body\">\n<group name=\"a\"><joint name=\"r_elbow\"/></group>\n<group name=\"a\"><joint name=\"l_elbow\"/></group>\n</robot>", "srdf_11.srdf:3"),
        ("a group state setting a joint outside its group", "<robot name=\"icub_upper_body\"><group name=\"a\"><joint name=\"r_elbow\"/></group>\n<group_state name=\"s\" group=\"a\"><joint name=\"l_elbow\" value=\"0.1\"/></group_state></robot>", "srdf_12.srdf:2"),
        ("groups nested 100 000 deep", "DEEP", "srdf_13.srdf:2"),
    ]
    .into_iter()
    .enumerate()
    {
        let name = format!("srdf_{k}.srdf");
        let deep = format!(
            "<robot name=\"icub_upper_body\">\n{}{}</robot>",
            "<group name=\"g\">".repeat(100_000),
            "</group>".repeat(100_000)
        );
        std::fs::write(dir.join(&name), if text == "DEEP" { &deep } else { text }).unwrap();
        cases.push(Case {
            what: format!("model-info --srdf with {what}"),
            args: ["model-info", "icub_upper_body.urdf", "--srdf", name.as_str()]
                .map(String::from)
                .to_vec(),
            names: names.into(),
        });
    }
    cases.extend(file_flag_cases(
        &["model-info"],
        "--srdf",
        &["no_such.srdf", ".", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &["model-info"],
        "--write-srdf",
        &[".", "map.json/x.srdf"],
    ));
    cases.push(Case {
        what: "model-info --write-description without --srdf".into(),
        args: [
            "model-info",
            "icub_upper_body.urdf",
            "--write-description",
            "d.ron",
        ]
        .map(String::from)
        .to_vec(),
        names: "--srdf".into(),
    });
    std::fs::write(
        dir.join("empty.srdf"),
        "<robot name=\"icub_upper_body\"></robot>",
    )
    .unwrap();
    cases.push(Case {
        what: "model-info --write-description of a .ron model".into(),
        args: [
            "model-info",
            "icub_upper_body.ron",
            "--srdf",
            "empty.srdf",
            "--write-description",
            "d.ron",
        ]
        .map(String::from)
        .to_vec(),
        names: "--write-description".into(),
    });
    for out in [".", "beside.ros.yaml", "linked.ros.yaml"] {
        for command in [
            vec!["fit-proxies", "icub_upper_body.urdf", "--out"],
            vec![
                "model-info",
                "icub_upper_body.urdf",
                "--srdf",
                "empty.srdf",
                "--write-description",
            ],
            vec!["model-info", "--write-srdf"],
        ] {
            cases.push(Case {
                what: format!("{} into {out}", command.join(" ")),
                args: command
                    .iter()
                    .map(|s| s.to_string())
                    .chain([out.to_string()])
                    .collect(),
                names: out.into(),
            });
        }
    }
    cases.push(Case {
        what: "fit-proxies of a model without meshes".into(),
        args: ["fit-proxies", "icub_upper_body.urdf"]
            .map(String::from)
            .to_vec(),
        names: "icub_upper_body.urdf".into(),
    });
    for (extra, names) in [
        (vec!["--spheres", "0"], "--spheres"),
        (vec!["--spheres", "x"], "--spheres"),
        (vec!["--spheres", "4"], "icub_upper_body.urdf"),
    ] {
        cases.push(Case {
            what: format!("fit-proxies {}", extra.join(" ")),
            args: ["fit-proxies", "icub_upper_body.urdf"]
                .into_iter()
                .chain(extra.iter().copied())
                .map(String::from)
                .collect(),
            names: names.into(),
        });
    }
    for bad in ["no_such.urdf", ".", "map.json", "world.ron"] {
        cases.push(Case {
            what: format!("fit-proxies {bad}"),
            args: ["fit-proxies", bad].map(String::from).to_vec(),
            names: bad.into(),
        });
    }
    cases.push(Case {
        what: "plan --repair without --world".into(),
        args: [
            "plan",
            "--map",
            "map.json",
            "--to",
            "0.1,0.2,0.3",
            "--repair",
        ]
        .map(String::from)
        .to_vec(),
        names: "--world".into(),
    });
    let scaling = ["map-scaling", spec, "--out-dir", "ms"];
    cases.extend(flag_cases(
        &scaling,
        "--points",
        &["0", "-1", "x", "100000000"],
    ));
    cases.extend(flag_cases(&scaling, "--threads", &["0", "-1", "x"]));
    cases.extend(file_flag_cases(
        &["map-scaling", spec],
        "--out-dir",
        &["posture.json"],
    ));
    cases.push(Case {
        what: "model-info --ros-postures of a model without named postures".into(),
        args: [
            "model-info",
            "icub_upper_body.urdf",
            "--ros-postures",
            "p.ros.yaml",
        ]
        .map(String::from)
        .to_vec(),
        names: "named postures".into(),
    });
    cases.extend(file_flag_cases(
        &["repair-map", "map.json", "--out", "r.json"],
        "--world",
        &["no_such.ron", ".", "map.json", "posture.json"],
    ));
    for bad in ["no_such.json", ".", "posture.json", "world.ron"] {
        cases.push(Case {
            what: format!("repair-map {bad}"),
            args: ["repair-map", bad, "--world", "world.ron", "--out", "r.json"]
                .map(String::from)
                .to_vec(),
            names: bad.into(),
        });
    }
    cases.extend(flag_cases(
        &[
            "repair-map",
            "map.json",
            "--world",
            "world.ron",
            "--out",
            "r.json",
        ],
        "--threads",
        &["0", "-1", "x"],
    ));
    cases.extend(flag_cases(
        &["model-info", "--ros-postures", "p.ros.yaml"],
        "--posture-seconds",
        &["0", "-1", "NaN", "inf", "x"],
    ));
    cases.extend(file_flag_cases(
        &["map-info", "map.json"],
        "--world",
        &["no_such.ron", ".", "map.json", "posture.json"],
    ));
    let plan = ["plan", "--map", "map.json"];
    cases.extend(flag_cases(
        &plan,
        "--to",
        &[
            "nan,0,0",
            "1,2",
            "a,b,c",
            "1,2,3,4",
            "inf,0,0",
            "no_such.json",
        ],
    ));
    let plan_to = ["plan", "--map", "map.json", "--to", "0.1,0.2,0.3"];
    cases.extend(flag_cases(
        &plan_to,
        "--tolerance",
        &["-1", "NaN", "inf", "0"],
    ));
    cases.extend(flag_cases(
        &plan_to,
        "--velocity",
        &["0", "-1", "NaN", "inf"],
    ));
    cases.extend(flag_cases(
        &plan_to,
        "--exact-tolerance",
        &["0", "-1", "NaN", "inf", "x"],
    ));
    cases.extend(flag_cases(&plan_to, "--seed", &["-5", "x"]));
    cases.extend(flag_cases(&plan_to, "--out", &["t.json"]));
    cases.extend(file_flag_cases(
        &plan_to,
        "--from",
        &["no_such.json", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &plan_to,
        "--world",
        &["no_such.ron", "map.json"],
    ));
    cases.extend(file_flag_cases(
        &["plan", "--to", "0,0,0"],
        "--map",
        &[
            "no_such.json",
            "posture.json",
            "world.ron",
            "/dev/zero",
            ".",
        ],
    ));
    let compare = ["compare-optimisers", "--spec", spec, "--out-dir", "cmp"];
    cases.extend(flag_cases(
        &compare,
        "--runs",
        &["0", "-1", "18446744073709551616"],
    ));
    cases.extend(flag_cases(&compare, "--runs", &["100000000"]));
    cases.extend(flag_cases(
        &compare,
        "--algos",
        &["", "xnes,nope", "xnes,xnes"],
    ));
    cases.extend(flag_cases(&compare, "--max-evals", &["0", "-1"]));
    cases.extend(flag_cases(&compare, "--seed", &["18446744073709551615"]));
    let optimise = ["optimise"];
    cases.extend(flag_cases(&optimise, "--algo", &["nope", ""]));
    cases.extend(flag_cases(
        &optimise,
        "--function",
        &["nope", "rotated-nope"],
    ));
    cases.extend(flag_cases(&optimise, "--dim", &["0", "-1", "100000000"]));
    cases.extend(flag_cases(&optimise, "--target", &["NaN", "x"]));
    cases.extend(flag_cases(
        &optimise,
        "--runs",
        &["0", "18446744073709551615"],
    ));
    cases.extend(flag_cases(
        &["optimise", "--runs", "3"],
        "--seed",
        &["18446744073709551615"],
    ));
    let map_json = read(&dir.join("map.json"));
    cases.extend(file_cases(
        &dir,
        &dir.join("map.json"),
        vec![(
            "a version written as a string".into(),
            map_json.replacen("\"version\":1", "\"version\":\"1\"", 1),
        )],
        &["map-info", "{}"],
    ));
    cases.extend(flag_cases(
        &optimise,
        "--max-evals",
        &["0", "18446744073709551615"],
    ));
    cases.extend(flag_cases(&optimise, "--sigma", &["0", "-1", "NaN", "inf"]));
    cases.extend(flag_cases(
        &optimise,
        "--population",
        &["0", "1", "10000000000000"],
    ));
    let speedup = ["speedup", spec, "--out-dir", "sp"];
    cases.extend(flag_cases(&speedup, "--points", &["0", "", "1,x", "-4"]));
    cases.extend(flag_cases(&speedup, "--threads", &["0", "1,0", "1000"]));
    cases.extend(flag_cases(&speedup, "--searches", &["0", "5000"]));
    let stand = ["stand-up", "--out", "su"];
    cases.extend(flag_cases(
        &stand,
        "--rollouts",
        &["0", "-1", "18446744073709551615"],
    ));
    cases.extend(flag_cases(
        &stand,
        "--bootstrap-rollouts",
        &["18446744073709551615"],
    ));
    let solve = ["solve", spec];
    cases.extend(flag_cases(&solve, "--algo", &["nope", "XNES2"]));
    cases.extend(flag_cases(
        &solve,
        "--max-evals",
        &["0", "-1", "18446744073709551615"],
    ));
    let stick = at("specs/taskmaps/stick.ron").to_string_lossy().to_string();
    let grasp = ["reach-grasp", stick.as_str()];
    cases.extend(flag_cases(&grasp, "--at", &["1,2", "nan,0,0", "0,0,0,0,0"]));
    cases.extend(flag_cases(
        &grasp,
        "--iterations",
        &["0", "-1", "18446744073709551615"],
    ));
    cases.extend(file_flag_cases(
        &grasp,
        "--world",
        &["no_such.ron", "map.json", "/dev/zero", "."],
    ));
    let studies = ["task-map-studies", "--out-dir", "st"];
    cases.extend(flag_cases(
        &studies,
        "--iterations",
        &["0", "18446744073709551615"],
    ));
    let acm = ["gen-acm"];
    cases.extend(flag_cases(
        &acm,
        "--samples",
        &["0", "-1", "18446744073709551615"],
    ));
    cases.extend(flag_cases(
        &acm,
        "--always-fraction",
        &["-0.1", "1.5", "NaN"],
    ));
    cases.extend(flag_cases(
        &["gen-acm", "--samples", "10"],
        "--posture",
        &["hom", "no_such_posture"],
    ));
    // --write-description needs a .ron description and a place beside it
    let description = at("models/panda/panda.ron").to_string_lossy().to_string();
    for (what, args, names) in [
        (
            "gen-acm --write-description of a URDF model",
            vec![
                "gen-acm",
                "icub_upper_body.urdf",
                "--samples",
                "10",
                "--write-description",
                "o.ron",
            ],
            "--write-description",
        ),
        (
            "gen-acm --write-description away from the description",
            vec![
                "gen-acm",
                description.as_str(),
                "--samples",
                "10",
                "--write-description",
                "elsewhere.ron",
            ],
            "elsewhere.ron",
        ),
    ] {
        cases.push(Case {
            what: what.into(),
            args: args.iter().map(|s| s.to_string()).collect(),
            names: names.into(),
        });
    }
    cases.extend(file_flag_cases(
        &["view", "--out", "v.html"],
        "--posture",
        &["no_such.json", "map.json", "/dev/zero"],
    ));
    cases.extend(file_flag_cases(
        &["view", "--out", "v.html"],
        "--map",
        &["posture.json"],
    ));
    cases.extend(file_flag_cases(
        &["view", "--out", "v.html"],
        "--world",
        &["map.json", "/dev/zero"],
    ));
    cases.extend(file_flag_cases(
        &["fk"],
        "--configs",
        &["map.json", "no_such.json", "."],
    ));

    // output paths: a symlink, a device, a directory, a path under a regular file
    std::os::unix::fs::symlink("/etc/hostname", dir.join("link.json")).unwrap();
    std::fs::create_dir_all(dir.join("a_directory")).unwrap();
    for out in [
        "link.json",
        "/dev/null",
        "a_directory",
        "posture.json/x.json",
    ] {
        for command in [
            vec!["solve", spec, "--out"],
            vec!["build-map", spec, "--points", "2", "--out"],
            vec![
                "build-map",
                spec,
                "--points",
                "2",
                "--checkpoint-every",
                "1",
                "--checkpoint",
            ],
            vec!["plan", "--map", "map.json", "--to", "0.1,0.2,0.3", "--out"],
            vec!["fk", "--configs", "configs.json", "--out"],
            vec!["collide", "--configs", "configs.json", "--out"],
            vec!["gen-acm", "--samples", "10", "--out"],
            vec!["view", "--out"],
            vec!["explore-task-map", stick.as_str(), "--out"],
            vec!["model-info", "--ros-postures"],
            vec!["repair-map", "map.json", "--world", "world.ron", "--out"],
        ] {
            cases.push(Case {
                what: format!("{} --out {out}", command[0]),
                args: command
                    .iter()
                    .map(|s| s.to_string())
                    .chain([out.to_string()])
                    .collect(),
                names: out.to_string(),
            });
        }
    }
    for command in [
        vec![
            "compare-optimisers",
            "--spec",
            spec,
            "--runs",
            "1",
            "--out-dir",
        ],
        vec!["stand-up", "--rollouts", "1", "--out"],
        vec!["task-map-studies", "--out-dir"],
        vec!["speedup", spec, "--points", "2", "--out-dir"],
    ] {
        cases.push(Case {
            what: format!("{} into a regular file", command[0]),
            args: command
                .iter()
                .map(|s| s.to_string())
                .chain(["posture.json".to_string()])
                .collect(),
            names: "posture.json".into(),
        });
    }

    // files written beside --out (the ROS 2 trajectory) that are a directory or a symlink
    std::fs::create_dir_all(dir.join("beside.ros.yaml")).unwrap();
    std::os::unix::fs::symlink("/etc/hostname", dir.join("linked.ros.yaml")).unwrap();
    std::fs::create_dir_all(dir.join("stand_up_out/trajectory.ros.yaml")).unwrap();
    for (command, names) in [
        (
            vec![
                "plan",
                "--map",
                "map.json",
                "--to",
                "0.1,0.2,0.3",
                "--out",
                "beside.csv",
            ],
            "beside.ros.yaml",
        ),
        (
            vec![
                "plan",
                "--map",
                "map.json",
                "--to",
                "0.1,0.2,0.3",
                "--out",
                "linked.csv",
            ],
            "linked.ros.yaml",
        ),
        (
            vec!["reach-grasp", stick.as_str(), "--out", "beside.csv"],
            "beside.ros.yaml",
        ),
        (
            vec!["stand-up", "--rollouts", "1", "--out", "stand_up_out"],
            "trajectory.ros.yaml",
        ),
    ] {
        cases.push(Case {
            what: format!("{} with {names} in the way", command[0]),
            args: command.iter().map(|s| s.to_string()).collect(),
            names: names.into(),
        });
    }

    // run them, two at a time
    let before: Vec<_> = listing(&dir);
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    let slowest = Mutex::new((0.0f64, String::new()));
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                while let Some(case) = cases.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let (code, stderr, secs) = run(&dir, &case.args);
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
                            "{} ({}): {p}\n    xtask {}\n    {}",
                            case.what,
                            case.names,
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
    assert!(cases.len() >= 400, "only {} cases", cases.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // failed runs wrote nothing: the directory holds only the inputs
    let after = listing(&dir);
    let new: Vec<_> = after.iter().filter(|p| !before.contains(p)).collect();
    assert!(new.is_empty(), "failed runs left files behind: {new:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every path under `dir`.
fn listing(dir: &Path) -> Vec<PathBuf> {
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

/// `kill -9` at any moment of `build-map` leaves the earlier map or a complete new one, and the
/// next run clears the temporary files the killed ones left.
#[test]
fn a_killed_build_leaves_the_old_map_or_a_complete_new_one() {
    let dir = std::env::temp_dir().join(format!("trm-kill-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let spec = root().join("specs/reach.ron");
    let build = |points: &str, seed: &str| {
        Command::new(env!("CARGO_BIN_EXE_xtask"))
            .args(["build-map", spec.to_str().unwrap(), "--points", points])
            .args(["--seed", seed, "--out", "map.json"])
            .current_dir(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("xtask starts")
    };
    assert!(build("3", "1").wait().unwrap().success());
    let old = std::fs::read(dir.join("map.json")).unwrap();
    let mut outcomes = (0, 0);
    for (k, delay) in [30u64, 120, 250, 400, 600, 900, 1300, 1800]
        .iter()
        .enumerate()
    {
        let mut child = build("40", &(k + 2).to_string());
        std::thread::sleep(Duration::from_millis(*delay));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        let now = std::fs::read(dir.join("map.json")).unwrap();
        if now == old {
            outcomes.0 += 1;
        } else {
            trm_roadmap::Roadmap::load(dir.join("map.json"))
                .expect("a changed map file is a complete map");
            outcomes.1 += 1;
        }
    }
    eprintln!(
        "killed builds: {} left the old map, {} a complete new one",
        outcomes.0, outcomes.1
    );
    // a run that finishes clears what the killed ones left
    assert!(build("3", "1").wait().unwrap().success());
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `kill -9` in the middle of a checkpointed build, then `--resume`: the same map file as an
/// uninterrupted build, byte for byte apart from the timing statistics. The kill comes as soon
/// as the first checkpoint is on disk; should a machine finish the whole build before that
/// (the map file is there), the test doubles the map and tries again, so its verdict does not
/// depend on the machine's speed.
#[test]
fn a_killed_build_resumes_to_the_uninterrupted_map() {
    let dir = std::env::temp_dir().join(format!("trm-resume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let spec = root().join("specs/reach.ron");
    let xtask = |args: &[&str]| {
        let mut command = Command::new(env!("CARGO_BIN_EXE_xtask"));
        command.args(args).current_dir(&dir).stderr(Stdio::null());
        command
    };
    let build = |points: &str, out: &str, more: &[&str]| {
        let mut args = vec!["build-map", spec.to_str().unwrap(), "--points", points];
        args.extend(["--out", out]);
        args.extend(more);
        xtask(&args)
    };
    let checkpoint = dir.join("killed.map.checkpoint");
    let mut points = 300;
    let killed_mid_way = loop {
        assert!(
            points <= 4800,
            "every build finished before it could be killed"
        );
        let _ = std::fs::remove_file(&checkpoint);
        let _ = std::fs::remove_file(dir.join("killed.map.json"));
        let mut child = build(
            &points.to_string(),
            "killed.map.json",
            &["--checkpoint-every", "20"],
        )
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
        let finished = loop {
            if checkpoint.exists() {
                break false;
            }
            if child.try_wait().unwrap().is_some() {
                break true;
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        if !finished && !dir.join("killed.map.json").exists() {
            break points;
        }
        points *= 2;
    };
    let status = build(&killed_mid_way.to_string(), "whole.map.json", &[])
        .stdout(Stdio::null())
        .status();
    assert!(status.unwrap().success());
    let resumed = xtask(&["build-map", "--resume", "killed.map.checkpoint"])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&resumed.stdout);
    assert!(resumed.status.success(), "{said}");
    eprintln!("{}", said.lines().next().unwrap_or_default());
    assert!(said.starts_with("resuming"), "{said}");
    let read = |name: &str| common::map_without_timings(&dir.join(name));
    assert!(read("whole.map.json") == read("killed.map.json"));
    let _ = std::fs::remove_dir_all(&dir);
}
