//! The CSV reader of every data file: any bytes are read or refused, never
//! a panic; an error that names a line names one inside the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate_core::data::{Table, TextTable};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let lines = text
        .replace("\r\n", "\n")
        .replace('\r', "\n")
        .lines()
        .count();
    for message in [
        Table::parse("f.csv", &text).err().map(|e| e.to_string()),
        TextTable::parse("f.csv", &text).err().map(|e| e.to_string()),
    ]
    .into_iter()
    .flatten()
    {
        assert!(message.starts_with("f.csv"), "{message}");
        let digits: String = message["f.csv".len()..]
            .strip_prefix(':')
            .unwrap_or("")
            .chars()
            .take_while(char::is_ascii_digit)
            .collect();
        if let Ok(line) = digits.parse::<usize>() {
            assert!(line >= 1 && line <= lines, "line {line} of {lines}: {message}");
        }
    }
});
