//! The wire crate's tests, one executable: the golden byte vectors, the decoders on bad input,
//! property tests of the codec, and the C header compiled against the Rust codec and fuzzed by
//! libFuzzer under sanitizers.

mod c_header;
mod c_libfuzzer;
mod decode_errors;
mod golden;
mod proptests;
