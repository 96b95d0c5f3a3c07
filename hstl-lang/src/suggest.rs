//! "Did you mean": the closest known name to an unknown one, within a budget of work.
//! The parser, the checker and the lints use it.

/// Names longer than this many characters get no "did you mean" help (and are never
/// suggested): a comparison costs the product of the two lengths.
pub const MAX_SUGGEST_CHARS: usize = 64;

/// The "did you mean" searches of one file compare at most this many pairs of characters
/// (and candidates) in all; past that they suggest nothing, so that a file with many
/// unknown names among many declared ones still checks in linear time.
pub const SUGGEST_BUDGET: u64 = 20_000_000;

/// The edit distance of `a` and `b` (insertions, deletions, substitutions and swaps of two
/// neighbours, each costing 1), if it is at most `limit`. `rows` is scratch space, reused
/// between calls.
fn distance_within(a: &[char], b: &[char], limit: usize, rows: &mut Vec<usize>) -> Option<usize> {
    if a.len().abs_diff(b.len()) > limit {
        return None;
    }
    let w = b.len() + 1;
    rows.clear();
    rows.resize(3 * w, 0);
    // Three rows: the one before the previous (for swaps), the previous and the current.
    let (mut older, mut prev, mut cur) = (0, w, 2 * w);
    for (j, cell) in rows[prev..prev + w].iter_mut().enumerate() {
        *cell = j;
    }
    for (i, &ca) in a.iter().enumerate() {
        rows[cur] = i + 1;
        let mut best = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let mut d = (rows[prev + j] + usize::from(ca != cb))
                .min(rows[prev + j + 1] + 1)
                .min(rows[cur + j] + 1);
            if i > 0 && j > 0 && ca == b[j - 1] && a[i - 1] == cb {
                d = d.min(rows[older + j - 1] + 1);
            }
            rows[cur + j + 1] = d;
            best = best.min(d);
        }
        if best > limit {
            return None;
        }
        (older, prev, cur) = (prev, cur, older);
    }
    let d = rows[prev + b.len()];
    (d <= limit).then_some(d)
}

/// The candidate closest to `name` (ties: the first in alphabetical order), if it is close
/// enough to be a typo: at most a third of the name's characters differ. Each compared
/// character pair and candidate costs one unit of `budget`; with the budget spent, nothing
/// is suggested.
pub(crate) fn closest<'a>(
    name: &str,
    candidates: impl Iterator<Item = &'a str>,
    budget: &mut u64,
) -> Option<&'a str> {
    let a: Vec<char> = name.chars().take(MAX_SUGGEST_CHARS + 1).collect();
    if a.len() > MAX_SUGGEST_CHARS || *budget == 0 {
        return None;
    }
    let len = a.len();
    let limit = (len / 3).max(1);
    let mut rows = Vec::new();
    let mut b: Vec<char> = Vec::with_capacity(MAX_SUGGEST_CHARS + 1);
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        if *budget == 0 {
            // A partial search could miss the closest name: suggest none.
            return None;
        }
        *budget -= 1;
        // A character takes one to four bytes: most candidates fail on their byte length.
        if c.len() + limit < len || c.len() > 4 * (len + limit) {
            continue;
        }
        b.clear();
        b.extend(c.chars().take(MAX_SUGGEST_CHARS + 1));
        if b.len() > MAX_SUGGEST_CHARS || b.len().abs_diff(len) > limit {
            continue;
        }
        *budget = budget.saturating_sub((len * b.len()) as u64);
        if let Some(d) = distance_within(&a, &b, limit, &mut rows)
            && d < len
            && best.is_none_or(|old| (d, c) < old)
        {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// At most `shown` names joined by commas, then how many there are in all.
pub(crate) fn some_names(names: &[&str], shown: usize) -> String {
    if names.len() <= shown {
        names.join(", ")
    } else {
        format!("{}, ... ({} in all)", names[..shown].join(", "), names.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn did_you_mean_counts_swaps_and_stays_bounded() {
        let unlimited = || u64::MAX;
        let params = ["alpha", "decay", "epsilon", "gamma", "min_epsilon"];
        let suggest = |name: &str| closest(name, params.iter().copied(), &mut unlimited());
        assert_eq!(suggest("gama"), Some("gamma"));
        assert_eq!(suggest("alpah"), Some("alpha"), "a swap of two neighbours costs one");
        assert_eq!(suggest("epsilno"), Some("epsilon"));
        assert_eq!(suggest("zzz"), None);
        // Too long to compare, and no budget: no suggestion, no work.
        let long = "a".repeat(100_000);
        assert_eq!(closest(&long, [long.as_str()].into_iter(), &mut unlimited()), None);
        assert_eq!(closest("gama", params.iter().copied(), &mut 0), None);
        // A search the budget cannot finish suggests nothing rather than a worse name.
        assert_eq!(closest("gama", params.iter().copied(), &mut 2), None);
        let mut budget = 1_000;
        assert_eq!(closest("gama", params.iter().copied(), &mut budget), Some("gamma"));
        assert!(budget < 1_000, "the search was charged");
    }
}
