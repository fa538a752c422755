//! "Did you mean" suggestions by edit distance.

/// The candidate closest to `word`, if it is close enough to be a likely
/// typo. Never one whose numbers differ from the word's (`diamond_r250um`
/// is not a typo of `diamond_r500um`: the suggestion would change a
/// dimension).
pub fn did_you_mean<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let n = word.chars().count();
    // One- and two-letter names are too short for a guess to mean anything.
    let limit = if n < 3 { 0 } else { (n / 3).max(1) };
    let numbers = numbers(word);
    candidates
        .into_iter()
        .filter(|c| *c != word && self::numbers(c) == numbers)
        .map(|c| (distance(&word.to_lowercase(), &c.to_lowercase()), c))
        .filter(|(d, _)| *d <= limit)
        .min_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(b.1)))
        .map(|(_, c)| c)
}

/// The candidates that are `word` with more words after it
/// (`fanuc_0i` → `fanuc_0i_lathe`, `fanuc_0i_mill`), in order: what a
/// name cut short may have meant.
pub fn completions<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Vec<&'a str> {
    let stem = format!("{}_", word.to_lowercase());
    let mut out: Vec<&str> = candidates
        .into_iter()
        .filter(|c| c.to_lowercase().starts_with(&stem))
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// What `word` may have meant, quoted: its likely typo, else the names it
/// may have been cut short from (`` `fanuc_0i_lathe` or `fanuc_0i_mill` ``).
pub fn meant<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str> + Clone,
) -> Option<String> {
    if let Some(s) = did_you_mean(word, candidates.clone()) {
        return Some(format!("`{s}`"));
    }
    let all = completions(word, candidates);
    let quoted: Vec<String> = all.iter().map(|c| format!("`{c}`")).collect();
    match quoted.as_slice() {
        [] => None,
        [one] => Some(one.clone()),
        [rest @ .., last] => Some(format!("{} or {last}", rest.join(", "))),
    }
}

/// The runs of digits in `word`, in order: `r250um` → ["250"].
fn numbers(word: &str) -> Vec<&str> {
    word.split(|c: char| !c.is_ascii_digit())
        .filter(|run| !run.is_empty())
        .collect()
}

/// Edit distance over characters where swapping two neighbours counts as
/// one edit (optimal string alignment): `mni` is one edit from `min`.
fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let w = b.len() + 1;
    let mut d = vec![0usize; (a.len() + 1) * w];
    for i in 0..=a.len() {
        d[i * w] = i;
    }
    for (j, slot) in d.iter_mut().enumerate().take(w) {
        *slot = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[(i - 1) * w + j] + 1)
                .min(d[i * w + j - 1] + 1)
                .min(d[(i - 1) * w + j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[(i - 2) * w + j - 2] + 1);
            }
            d[i * w + j] = v;
        }
    }
    d[a.len() * w + b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(did_you_mean("radus", ["radius", "conic"]), Some("radius"));
        assert_eq!(
            did_you_mean("nose_radus", ["nose_radius", "clearance"]),
            Some("nose_radius")
        );
        assert_eq!(did_you_mean("zzz", ["radius", "conic"]), None);
        assert_eq!(did_you_mean("mni", ["min", "mm"]), Some("min"));
        assert_eq!(did_you_mean("x", ["a", "y"]), None);
    }

    #[test]
    fn never_across_differing_numbers_and_completes_a_name_cut_short() {
        assert_eq!(did_you_mean("diamond_r250um", ["diamond_r500um"]), None);
        assert_eq!(
            did_you_mean("diamnd_r500um", ["diamond_r500um"]),
            Some("diamond_r500um")
        );
        assert_eq!(
            completions("fanuc_0i", ["fanuc_0i_mill", "fanuc_0i_lathe", "fanuc"]),
            ["fanuc_0i_lathe", "fanuc_0i_mill"]
        );
        assert!(completions("fanuc", ["fanucs"]).is_empty());
    }
}
