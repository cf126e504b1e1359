//! Fuzz target: the Obj loader must return Ok or Err, never panic, on any bytes.
#![no_main]

use fairmesh::io::{load_from_bytes, Format, LoadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = load_from_bytes(data, Format::Obj, "fuzz.obj", &LoadOptions::default());
});
