//! Summaries and tables of a run: per family valid, solved, median and p95 time, length; CSV;
//! side by side with a peer.

use crate::run::Run;
use crate::solve::Outcome;

/// What a family (or a whole set) came to, as the field reports planners.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    /// Problems.
    pub problems: usize,
    /// Valid problems (start and goal free and within limits).
    pub valid: usize,
    /// Valid problems solved.
    pub solved: usize,
    /// Median and 95th percentile of the solved problems' times, s (`None` when none solved).
    pub time: Option<(f64, f64)>,
    /// Median of the solved problems' planning times without simplification, s.
    pub plan_time: Option<f64>,
    /// Median path length of the solved problems, rad.
    pub length: Option<f64>,
    /// Median collision checks of the solved problems.
    pub checks: Option<f64>,
}

/// The `q`-quantile (0..=1, nearest rank) of `values`; `None` for none.
pub fn quantile(values: &[f64], q: f64) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let k = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len().max(1));
    sorted.get(k - 1).copied()
}

impl Summary {
    /// The summary of `outcomes`.
    pub fn of<'a>(outcomes: impl IntoIterator<Item = &'a Outcome>) -> Self {
        let outcomes: Vec<&Outcome> = outcomes.into_iter().collect();
        let solved: Vec<&&Outcome> = outcomes.iter().filter(|o| o.valid && o.solved).collect();
        let of = |f: &dyn Fn(&Outcome) -> f64| solved.iter().map(|o| f(o)).collect::<Vec<f64>>();
        let times = of(&|o| o.seconds);
        Summary {
            problems: outcomes.len(),
            valid: outcomes.iter().filter(|o| o.valid).count(),
            solved: solved.len(),
            time: quantile(&times, 0.5).zip(quantile(&times, 0.95)),
            plan_time: quantile(&of(&|o| o.seconds - o.simplify_seconds), 0.5),
            length: quantile(&of(&|o| o.length), 0.5),
            checks: quantile(&of(&|o| o.checks as f64), 0.5),
        }
    }
}

/// The runs as CSV: family, problem, valid, solved, seconds, simplify_seconds (of seconds),
/// length, waypoints, checks, verified, note.
pub fn runs_csv(runs: &[Run]) -> String {
    use std::fmt::Write as _;
    let mut csv = String::from(
        "family,problem,valid,solved,seconds,simplify_seconds,length,waypoints,checks,verified,note\n",
    );
    for r in runs {
        let o = &r.outcome;
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{},{},{},{},{},\"{}\"",
            r.family,
            r.index,
            o.valid,
            o.solved,
            o.seconds,
            o.simplify_seconds,
            o.length,
            o.waypoints,
            o.checks,
            r.verified.map_or(String::new(), |v| v.to_string()),
            o.note.replace('"', "'")
        );
    }
    csv
}

/// Formats a time in milliseconds with two decimals ("—" for none).
fn ms(seconds: Option<f64>) -> String {
    seconds.map_or("—".to_string(), |s| format!("{:.2}", s * 1e3))
}

/// A path length, rad, or a dash.
fn length(rad: Option<f64>) -> String {
    rad.map_or("—".into(), |l| format!("{l:.2}"))
}

/// The field's per-family table in markdown: valid, solved, median and p95 time, median path
/// length and collision checks, one row per family (in the order first met) and one for all.
pub fn markdown_table<'a>(outcomes: impl IntoIterator<Item = (&'a str, &'a Outcome)>) -> String {
    use std::fmt::Write as _;
    let outcomes: Vec<(&str, &Outcome)> = outcomes.into_iter().collect();
    let mut md = String::from(
        "| family | valid | solved | median ms | p95 ms | median length (rad) | median checks |\n|---|---|---|---|---|---|---|\n",
    );
    let mut row = |name: &str, s: Summary| {
        let _ = writeln!(
            md,
            "| {name} | {}/{} | {}/{} ({:.1} %) | {} | {} | {} | {} |",
            s.valid,
            s.problems,
            s.solved,
            s.valid,
            100.0 * s.solved as f64 / s.valid.max(1) as f64,
            ms(s.time.map(|t| t.0)),
            ms(s.time.map(|t| t.1)),
            length(s.length),
            s.checks
                .filter(|&c| c > 0.0)
                .map_or("—".into(), |c| format!("{c:.0}"))
        );
    };
    for family in families(&outcomes) {
        row(
            family,
            Summary::of(outcomes.iter().filter(|o| o.0 == family).map(|o| o.1)),
        );
    }
    row("all", Summary::of(outcomes.iter().map(|o| o.1)));
    md
}

/// The families of `outcomes` in the order first met.
fn families<'a>(outcomes: &[(&'a str, &Outcome)]) -> Vec<&'a str> {
    let mut names: Vec<&str> = Vec::new();
    for (f, _) in outcomes {
        if !names.contains(f) {
            names.push(f);
        }
    }
    names
}

/// Two planners side by side per family, in markdown: each one's solved share of the problems
/// both call valid, its median planning time without simplification, its median and p95 time
/// with it, its median path length, and the ratios `ours / theirs`; then a line with both
/// planners' times and lengths over the problems both solve.
pub fn side_by_side<'a>(
    (ours, our_name): (&[(&'a str, &'a Outcome)], &str),
    (theirs, their_name): (&[(&'a str, &'a Outcome)], &str),
) -> String {
    use std::fmt::Write as _;
    let mut md = format!(
        "| family | both valid | {our_name} solved | {their_name} solved | {our_name} plan-only median ms | {their_name} plan-only median ms | {our_name} median ms | {their_name} median ms | median ratio | {our_name} p95 ms | {their_name} p95 ms | p95 ratio | {our_name} median length (rad) | {their_name} median length (rad) | length ratio |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
    );
    let mut row = |name: &str, pairs: Vec<(&Outcome, &Outcome)>| {
        let both: Vec<_> = pairs.iter().filter(|(a, b)| a.valid && b.valid).collect();
        let (a, b) = (
            Summary::of(both.iter().map(|p| p.0)),
            Summary::of(both.iter().map(|p| p.1)),
        );
        let ratio = |x: Option<f64>, y: Option<f64>| {
            x.zip(y)
                .filter(|(_, y)| *y > 0.0)
                .map_or("—".into(), |(x, y)| format!("{:.1}×", x / y))
        };
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            both.len(),
            a.solved,
            b.solved,
            ms(a.plan_time),
            ms(b.plan_time),
            ms(a.time.map(|t| t.0)),
            ms(b.time.map(|t| t.0)),
            ratio(a.time.map(|t| t.0), b.time.map(|t| t.0)),
            ms(a.time.map(|t| t.1)),
            ms(b.time.map(|t| t.1)),
            ratio(a.time.map(|t| t.1), b.time.map(|t| t.1)),
            length(a.length),
            length(b.length),
            ratio(a.length, b.length),
        );
    };
    let pair = |family: Option<&str>| -> Vec<(&Outcome, &Outcome)> {
        ours.iter()
            .zip(theirs)
            .filter(|((f, _), _)| family.is_none_or(|name| *f == name))
            .map(|((_, a), (_, b))| (*a, *b))
            .collect()
    };
    for family in families(ours) {
        row(family, pair(Some(family)));
    }
    row("all", pair(None));
    // each planner's times above are over the problems it solves; the problems only one of
    // them solves are often its slowest, so the two also over the same problems
    let both: Vec<_> = (pair(None).into_iter())
        .filter(|(a, b)| a.valid && a.solved && b.valid && b.solved)
        .collect();
    let (a, b) = (
        Summary::of(both.iter().map(|p| p.0)),
        Summary::of(both.iter().map(|p| p.1)),
    );
    if let (Some(x), Some(y)) = (a.time, b.time) {
        let _ = writeln!(
            md,
            "\nOn the {} problems both solve: {our_name} median {} / p95 {} ms (plan-only {}), {their_name} median {} / p95 {} ms (plan-only {}); median path lengths {} and {} rad.",
            both.len(),
            ms(Some(x.0)),
            ms(Some(x.1)),
            ms(a.plan_time),
            ms(Some(y.0)),
            ms(Some(y.1)),
            ms(b.plan_time),
            length(a.length),
            length(b.length),
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outcome(solved: bool, ms: f64) -> Outcome {
        Outcome {
            valid: true,
            solved,
            seconds: ms * 1e-3,
            length: 1.0,
            ..Default::default()
        }
    }

    /// The line over the problems both solve leaves out a slow problem only one solves,
    /// which the table's own medians keep.
    #[test]
    fn both_planners_are_also_timed_on_the_problems_both_solve() {
        let ours = [outcome(true, 1.0), outcome(true, 3.0), outcome(true, 100.0)];
        let theirs = [outcome(true, 2.0), outcome(true, 2.0), outcome(false, 0.0)];
        let tag = |o: &[Outcome; 3]| -> Vec<(&'static str, Outcome)> {
            o.iter().map(|x| ("box", x.clone())).collect()
        };
        let (a, b) = (tag(&ours), tag(&theirs));
        let a: Vec<(&str, &Outcome)> = a.iter().map(|(f, o)| (*f, o)).collect();
        let b: Vec<(&str, &Outcome)> = b.iter().map(|(f, o)| (*f, o)).collect();
        let md = side_by_side((&a, "trm"), (&b, "VAMP"));
        // the table: trm's median over its three solved problems
        assert!(md.contains("| all | 3 | 3 | 2 |"), "{md}");
        assert!(md.contains("| 3.00 | 2.00 |"), "{md}");
        assert!(
            md.contains("On the 2 problems both solve: trm median 1.00 / p95 3.00 ms"),
            "{md}"
        );
        assert!(md.contains("VAMP median 2.00 / p95 2.00 ms"), "{md}");
    }
}
