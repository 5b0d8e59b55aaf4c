//! The study-manifest reader of `palpate run`: any text is parsed and, when
//! it parses, validated (references, laws, model settings), never a panic;
//! every error names the manifest.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate_studies::study::manifest::Manifest;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    // A folder that does not exist: data files are reported missing, not read.
    let path = Path::new("/nonexistent-palpate-fuzz/s.toml");
    let error = match Manifest::parse(path, text) {
        Err(e) => e,
        Ok(m) => match m.validate(path) {
            Err(e) => e,
            Ok(_) => return,
        },
    };
    let message = error.to_string();
    assert!(message.contains("s.toml"), "{message}");
});
