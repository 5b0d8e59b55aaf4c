//! The design-manifest reader of `palpate doe`: any text is parsed and its
//! design built (sizes and generators checked before allocating), never a
//! panic or an allocation failure; every error names the manifest.
#![no_main]

use libfuzzer_sys::fuzz_target;
use palpate_studies::cli::doe::read_design;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Err(e) = read_design(Path::new("d.toml"), text) {
        let message = e.to_string();
        assert!(message.starts_with("d.toml"), "{message}");
    }
});
