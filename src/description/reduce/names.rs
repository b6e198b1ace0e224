//! Names offered when one asked for is not there: the closest first.

use super::*;

/// How many names [`closest_first`] shows before it counts the rest.
pub(super) const SHOWN: usize = 20;

/// `names` (duplicates once), closest to `name` first (case-insensitive): by
/// the characters of `name` a name lacks in order (|name| − their longest
/// common subsequence: 'panda_tcp' is all in 'panda_hand_tcp'), then by the
/// edit distance, then in their given order; the first `shown` of them
/// quoted, then how many more there are.
pub(super) fn closest_first<'a>(
    name: &str,
    names: impl Iterator<Item = &'a str>,
    shown: usize,
) -> String {
    let mut seen: Vec<&str> = Vec::new();
    for n in names {
        if !seen.contains(&n) {
            seen.push(n);
        }
    }
    let wanted = name.to_lowercase();
    let mut ranked: Vec<(usize, usize, usize, &str)> = seen
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let other = n.to_lowercase();
            let lacks = wanted.chars().count() - common_subsequence(&wanted, &other);
            (lacks, edit_distance(&wanted, &other), i, *n)
        })
        .collect();
    ranked.sort();
    let mut out = names_list(ranked.iter().take(shown).map(|r| r.3));
    if ranked.len() > shown {
        out.push_str(&format!(" and {} more", ranked.len() - shown));
    }
    out
}

/// The length of the longest common subsequence of `a` and `b` (characters).
pub(super) fn common_subsequence(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row = alloc::vec![0usize; b.len() + 1];
    for ca in a.chars() {
        let mut diagonal = 0;
        for (j, cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = if ca == *cb {
                diagonal + 1
            } else {
                above.max(row[j])
            };
            diagonal = above;
        }
    }
    row[b.len()]
}

/// The Levenshtein distance of `a` and `b` (insertions, deletions and
/// substitutions of characters), one row at a time.
pub(super) fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitute = previous + usize::from(ca != *cb);
            previous = row[j + 1];
            row[j + 1] = substitute.min(previous + 1).min(row[j] + 1);
        }
    }
    row[b.len()]
}
