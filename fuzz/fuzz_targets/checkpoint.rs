//! Build checkpoint (binary): a checkpoint or an error. The input is the encoded content,
//! framed here with the format header and a valid checksum so the decoder and the checks behind
//! them are what gets fuzzed; a checkpoint that reads is written back and reads again unchanged.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| trm_fuzz_checks::checkpoint(data));
