//! Properties of the CSV reader (`Table`, `TextTable`), on generated input:
//!
//! * arbitrary bytes never panic: they are read or refused with an error;
//! * a valid table written in any of the accepted spellings (comments, blank
//!   lines, quoted fields, a byte-order mark, LF / CRLF / CR line endings)
//!   reads back to the same names, the same values bit for bit, and the
//!   line of each row;
//! * every error that names a line names one inside the file, and a defect
//!   put on a known line is reported on that line.

use palpate_core::data::{DataError, Table, TextTable};
use proptest::prelude::*;

/// The line an error names, if it names one.
fn error_line(e: &DataError) -> Option<usize> {
    let text = e.to_string();
    let rest = text.strip_prefix("t.csv:")?;
    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// Lines of a text as the reader counts them (each of LF, CRLF, CR ends one).
fn line_count(text: &str) -> usize {
    text.replace("\r\n", "\n")
        .replace('\r', "\n")
        .lines()
        .count()
}

/// A generated valid table and how it is spelled.
#[derive(Debug, Clone)]
struct Spelled {
    names: Vec<String>,
    rows: Vec<Vec<f64>>,
    bom: bool,
    ending: &'static str,
    /// Before each row: a comment line, a blank line, or nothing.
    extra: Vec<u8>,
    quoted: bool,
}

impl Spelled {
    /// The file text and the line of each row.
    fn text(&self) -> (String, Vec<usize>) {
        let mut s = String::new();
        let mut line = 0;
        if self.bom {
            s.push('\u{feff}');
        }
        s.push_str("# generated");
        s.push_str(self.ending);
        line += 1;
        s.push_str(&self.names.join(","));
        s.push_str(self.ending);
        line += 1;
        let mut lines = Vec::new();
        for (r, row) in self.rows.iter().enumerate() {
            match self.extra[r] % 3 {
                0 => {
                    s.push_str("# note");
                    s.push_str(self.ending);
                    line += 1;
                }
                1 => {
                    s.push_str("   ");
                    s.push_str(self.ending);
                    line += 1;
                }
                _ => {}
            }
            let fields: Vec<String> = row
                .iter()
                .map(|v| {
                    if self.quoted {
                        format!("\"{v}\"")
                    } else {
                        format!("{v}")
                    }
                })
                .collect();
            s.push_str(&fields.join(", "));
            s.push_str(self.ending);
            line += 1;
            lines.push(line);
        }
        (s, lines)
    }
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e6f64..1e6,
        any::<f64>().prop_filter("finite", |v| v.is_finite()),
        Just(0.0),
        Just(-0.0),
        Just(f64::MIN_POSITIVE),
    ]
}

fn spelled() -> impl Strategy<Value = Spelled> {
    (1usize..5, 1usize..20).prop_flat_map(|(cols, rows)| {
        (
            proptest::sample::subsequence(
                vec![
                    "displacement_mm",
                    "force_N",
                    "stretch",
                    "stress_MPa",
                    "x",
                    "y_1",
                ],
                cols,
            ),
            proptest::collection::vec(proptest::collection::vec(finite(), cols), rows),
            any::<bool>(),
            prop_oneof![Just("\n"), Just("\r\n"), Just("\r")],
            proptest::collection::vec(any::<u8>(), rows),
            any::<bool>(),
        )
            .prop_map(|(names, rows, bom, ending, extra, quoted)| Spelled {
                names: names.into_iter().map(String::from).collect(),
                rows,
                bom,
                ending,
                extra,
                quoted,
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        let lines = line_count(&text);
        let errors = [Table::parse("t.csv", &text).err(), TextTable::parse("t.csv", &text).err()];
        for e in errors.iter().flatten() {
            if let Some(l) = error_line(e) {
                prop_assert!(l >= 1 && l <= lines, "line {l} of {lines}: {e}");
            }
        }
    }

    #[test]
    fn csv_like_text_never_panics_and_errors_stay_in_the_file(
        cells in proptest::collection::vec(
            prop_oneof![
                Just("time_s".to_string()), Just("force_N".to_string()), Just(",".to_string()),
                Just("\n".to_string()), Just("\r".to_string()), Just("#".to_string()),
                Just("\"".to_string()), Just("1.5".to_string()), Just("-0".to_string()),
                Just("nan".to_string()), Just("inf".to_string()), Just("1e400".to_string()),
                Just(" ".to_string()), Just("\u{feff}".to_string()), "[a-z0-9.]{0,4}",
            ],
            0..60,
        )
    ) {
        let text: String = cells.concat();
        let lines = line_count(&text);
        if let Err(e) = Table::parse("t.csv", &text) {
            if let Some(l) = error_line(&e) {
                prop_assert!(l >= 1 && l <= lines, "line {l} of {lines}: {e}\n{text:?}");
            }
        }
    }

    #[test]
    fn a_valid_table_reads_back_exactly(t in spelled()) {
        let (text, lines) = t.text();
        let table = Table::parse("t.csv", &text).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(&table.names, &t.names);
        prop_assert_eq!(&table.lines, &lines);
        for (k, col) in table.columns.iter().enumerate() {
            for (r, v) in col.iter().enumerate() {
                prop_assert_eq!(v.to_bits(), t.rows[r][k].to_bits(), "row {} column {}", r, k);
            }
        }
    }

    #[test]
    fn a_defect_is_reported_on_its_line(t in spelled(), which in any::<prop::sample::Index>(), kind in 0usize..3) {
        let (text, lines) = t.text();
        let r = which.index(t.rows.len());
        // Rewrite row r: a word in place of a number, a missing field, an infinity.
        let ending = t.ending;
        let mut out: Vec<String> = text.split(ending).map(String::from).collect();
        let at = lines[r] - 1;
        let mut fields: Vec<String> = out[at].split(',').map(String::from).collect();
        let bad = match kind {
            0 => { fields[0] = "abc".into(); fields.join(",") }
            1 => { fields.push("1".into()); fields.join(",") }
            _ => { fields[0] = "inf".into(); fields.join(",") }
        };
        out[at] = bad;
        let text = out.join(ending);
        let e = Table::parse("t.csv", &text).expect_err("a defect was accepted");
        prop_assert_eq!(error_line(&e), Some(lines[r]), "{}", e);
    }
}
