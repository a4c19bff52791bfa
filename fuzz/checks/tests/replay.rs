//! Every fuzz target's check on its seed files and on seeded mutations of them (byte flips,
//! cuts, repeats, inserted syntax), on stable and in the quick suite: the same properties the
//! libFuzzer campaign checks (`fuzz/run.sh`), a thousand inputs per target, reproducible.

use std::path::{Path, PathBuf};

use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trm_fuzz_checks::TARGETS;

/// Mutated inputs per target.
const MUTATIONS: usize = 1000;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The seed files of `target`: fuzz/seeds.txt's globs and fuzz/seeds/TARGET/*.
fn seeds(target: &str) -> Vec<PathBuf> {
    let root = root();
    let list = std::fs::read_to_string(root.join("fuzz/seeds.txt")).unwrap();
    let mut patterns: Vec<String> = list
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .filter_map(|l| l.split_once(' '))
        .filter(|(t, _)| *t == target)
        .map(|(_, glob)| root.join(glob.trim()).display().to_string())
        .collect();
    patterns.push(
        root.join("fuzz/seeds")
            .join(target)
            .join("*")
            .display()
            .to_string(),
    );
    let mut files: Vec<PathBuf> = patterns
        .iter()
        .flat_map(|p| glob::glob(p).unwrap().map(Result::unwrap))
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// Pieces of syntax worth inserting into text formats.
const TOKENS: &[&[u8]] = &[
    b"{",
    b"}",
    b"[",
    b"]",
    b"(",
    b")",
    b"<",
    b">",
    b"/>",
    b"\"",
    b",",
    b":",
    b"-",
    b"NaN",
    b"inf",
    b"-1e309",
    b"1e309",
    b"0",
    b"-1",
    b"\n",
    b"  ",
    b"</robot>",
    b"<link name=\"\"/>",
    b"Some(",
    b"None",
    b"true",
    b"null",
    b"- ",
    b"#",
    b"\\",
];

/// One to four random edits of `seed`.
fn mutate(seed: &[u8], rng: &mut impl Rng) -> Vec<u8> {
    let mut data = seed.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        let at = if data.is_empty() {
            0
        } else {
            rng.random_range(0..=data.len())
        };
        match rng.random_range(0..5) {
            0 if at < data.len() => data[at] ^= 1 << rng.random_range(0..8),
            1 => {
                let end = (at + rng.random_range(1..64)).min(data.len());
                data.drain(at..end);
            }
            2 => {
                let end = (at + rng.random_range(1..256)).min(data.len());
                let piece = data[at..end].to_vec();
                data.splice(at..at, piece);
            }
            3 => {
                let token = TOKENS[rng.random_range(0..TOKENS.len())];
                data.splice(at..at, token.iter().copied());
            }
            _ => data.truncate(at),
        }
    }
    data
}

#[test]
fn every_target_holds_on_its_seeds_and_their_mutations() {
    for (index, &(name, check)) in TARGETS.iter().enumerate() {
        let files = seeds(name);
        let inputs: Vec<Vec<u8>> = files.iter().map(|f| std::fs::read(f).unwrap()).collect();
        if name != "checkpoint" && name != "mesh" {
            assert!(!inputs.is_empty(), "fuzz target {name} has no seed file");
        }
        for (file, input) in files.iter().zip(&inputs) {
            eprintln!("{name}: {}", file.display());
            check.run(input);
        }
        let mut rng = ChaCha8Rng::seed_from_u64(index as u64);
        for i in 0..MUTATIONS {
            let seed = inputs
                .get(i % inputs.len().max(1))
                .map_or(&[][..], Vec::as_slice);
            let input = mutate(seed, &mut rng);
            // a failure names the input, which can then be replayed by the fuzz target
            let outcome = std::panic::catch_unwind(|| check.run(&input));
            if outcome.is_err() {
                let path = std::env::temp_dir().join(format!("trm-fuzz-{name}-{i}"));
                std::fs::write(&path, &input).unwrap();
                panic!(
                    "fuzz target {name} failed on mutation {i}, saved as {} (replay: fuzz/run.sh {name} {})",
                    path.display(),
                    path.display()
                );
            }
        }
    }
}

#[test]
fn the_fuzz_targets_the_script_and_the_checks_agree() {
    let root = root();
    let mut files: Vec<String> = std::fs::read_dir(root.join("fuzz/fuzz_targets"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let mut checks: Vec<String> = TARGETS.iter().map(|(n, _)| n.to_string()).collect();
    checks.sort();
    assert_eq!(
        files, checks,
        "fuzz/fuzz_targets/*.rs against trm_fuzz_checks::TARGETS"
    );
    let script = std::fs::read_to_string(root.join("fuzz/run.sh")).unwrap();
    let list = script
        .split("targets=(")
        .nth(1)
        .unwrap()
        .split(')')
        .next()
        .unwrap();
    let mut listed: Vec<String> = list.split_whitespace().map(String::from).collect();
    listed.sort();
    assert_eq!(
        listed, checks,
        "fuzz/run.sh's targets against trm_fuzz_checks::TARGETS"
    );
    let manifest = std::fs::read_to_string(root.join("fuzz/Cargo.toml")).unwrap();
    for name in &checks {
        assert!(
            manifest.contains(&format!("name = \"{name}\"")),
            "fuzz/Cargo.toml has no [[bin]] {name}"
        );
    }
}
