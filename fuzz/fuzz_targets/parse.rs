//! Any bytes: parsing, validating and rendering the diagnostics never panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = a2ml_core::language::parse_ast(&text, None);
    if let Err(d) = a2ml_core::language::parse(&text, None) {
        let _ = d.to_string();
    }
});
