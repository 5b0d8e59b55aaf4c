//! Replicates: several files recording one material, named by a pattern
//! with wildcards (`tests/EF10_0T_*.csv`), and the batch each belongs to,
//! declared (`batch=A`) or read from the file names (`EF10_0T_A1` ...
//! `EF10_0T_B5`: batches `A` and `B`).

use std::path::{Path, PathBuf};

/// Whether `pattern` has wildcards (`*` or `?`).
pub fn is_pattern(pattern: &str) -> bool {
    pattern.contains(['*', '?'])
}

/// Whether `name` matches `pattern` (`*` any run of characters, `?` one
/// character). Written here: one directory level of two wildcards needs no
/// glob crate.
pub fn matches(pattern: &str, name: &str) -> bool {
    let p: Vec<char> = pattern.chars().collect();
    let n: Vec<char> = name.chars().collect();
    // Iterative matching with the last `*` as the backtrack point.
    let (mut i, mut j) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while j < n.len() {
        if i < p.len() && (p[i] == '?' || p[i] == n[j]) {
            i += 1;
            j += 1;
        } else if i < p.len() && p[i] == '*' {
            star = Some((i, j));
            i += 1;
        } else if let Some((si, sj)) = star {
            i = si + 1;
            j = sj + 1;
            star = Some((si, sj + 1));
        } else {
            return false;
        }
    }
    p[i..].iter().all(|&c| c == '*')
}

/// The files `pattern` names, sorted by name: the file itself when it has
/// no wildcard; wildcards only in the file name, not in its folders. `Err`
/// when nothing matches, listing the folder's files.
pub fn expand(pattern: &str) -> anyhow::Result<Vec<PathBuf>> {
    if !is_pattern(pattern) {
        return Ok(vec![PathBuf::from(pattern)]);
    }
    let path = Path::new(pattern);
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let file = path
        .file_name()
        .and_then(|f| f.to_str())
        .unwrap_or_default();
    anyhow::ensure!(
        !is_pattern(&dir.to_string_lossy()),
        "{pattern}: wildcards only in the file name, not in its folders ({})",
        dir.display()
    );
    let entries = std::fs::read_dir(dir)
        .map_err(|e| anyhow::anyhow!("{pattern}: cannot list {}: {e}", dir.display()))?;
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().map(|t| t.is_file()).unwrap_or(false))
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .collect();
    names.sort();
    let found: Vec<PathBuf> = names
        .iter()
        .filter(|n| matches(file, n))
        .map(|n| dir.join(n))
        .collect();
    if found.is_empty() {
        let shown: Vec<&str> = names.iter().take(8).map(String::as_str).collect();
        anyhow::bail!(
            "{pattern}: no file of {} matches `{file}` (it has {}{})",
            dir.display(),
            if shown.is_empty() {
                "no files".to_string()
            } else {
                shown.join(", ")
            },
            if names.len() > shown.len() {
                ", ..."
            } else {
                ""
            }
        );
    }
    Ok(found)
}

/// The batch of each file read from the names (stems) of replicate files:
/// each stem without its trailing test number (`EF10_0T_A3` ->
/// `EF10_0T_A`), then what differs after the part all share (`A`, `B`).
/// `None` when the names make fewer than two batches, or a batch of one
/// file.
pub fn batches_from_names(stems: &[String]) -> Option<Vec<String>> {
    let cut: Vec<&str> = stems
        .iter()
        .map(|s| s.trim_end_matches(|c: char| c.is_ascii_digit()))
        .map(|s| s.trim_end_matches(['_', '-', ' ', '.']))
        .collect();
    let mut distinct: Vec<&str> = cut.clone();
    distinct.sort();
    distinct.dedup();
    if distinct.len() < 2 || distinct.iter().any(|d| d.is_empty()) {
        return None;
    }
    if distinct
        .iter()
        .any(|d| cut.iter().filter(|c| *c == d).count() < 2)
    {
        return None;
    }
    // The longest common prefix, in characters.
    let first: Vec<char> = distinct[0].chars().collect();
    let common = distinct.iter().skip(1).fold(first.len(), |n, d| {
        d.chars()
            .zip(&first)
            .take(n)
            .take_while(|(a, b)| a == *b)
            .count()
    });
    let label = |c: &str| -> String {
        let rest: String = c.chars().skip(common).collect();
        let rest = rest.trim_start_matches(['_', '-', ' ', '.']);
        if rest.is_empty() {
            c.to_string()
        } else {
            rest.to_string()
        }
    };
    let labels: Vec<String> = cut.iter().map(|c| label(c)).collect();
    Some(labels)
}

/// The stem of a file path (`dir/EF10_0T_A1.csv` -> `EF10_0T_A1`).
pub fn stem(file: &str) -> String {
    Path::new(file)
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| file.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards_match_as_a_shell_does() {
        assert!(matches("*.csv", "EF10_0T_A1.csv"));
        assert!(matches("EF10_0T_?1.csv", "EF10_0T_B1.csv"));
        assert!(!matches("EF10_0T_?1.csv", "EF10_0T_B2.csv"));
        assert!(matches("*_A*", "EF10_0T_A1.csv"));
        assert!(!matches("*_A*", "EF10_0T_B1.csv"));
        assert!(matches("a*b*c", "aXXbYYc"));
        assert!(!matches("a*b*c", "aXXbYY"));
        assert!(matches("*", ""));
    }

    #[test]
    fn batches_are_read_from_the_names_or_not_at_all() {
        let stems = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
        assert_eq!(
            batches_from_names(&stems(&[
                "EF10_0T_A1",
                "EF10_0T_A2",
                "EF10_0T_B1",
                "EF10_0T_B2"
            ])),
            Some(stems(&["A", "A", "B", "B"]))
        );
        assert_eq!(
            batches_from_names(&stems(&["run_x_1", "run_x_2", "run_yy_1", "run_yy_2"])),
            Some(stems(&["x", "x", "yy", "yy"]))
        );
        // One batch, or a batch of a single file: none.
        assert_eq!(batches_from_names(&stems(&["s1", "s2", "s3"])), None);
        assert_eq!(batches_from_names(&stems(&["A1", "A2", "B1"])), None);
    }
}
