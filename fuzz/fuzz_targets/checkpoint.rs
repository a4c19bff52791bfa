//! Build checkpoint (binary): a checkpoint or an error. The input is the encoded content,
//! framed here with the format header and a valid checksum so the decoder and the checks behind
//! them are what gets fuzzed; a checkpoint that reads is written back and reads again unchanged.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|content: &[u8]| {
    let path = Path::new("fuzz.checkpoint");
    // the header alone: the framing of an empty value, without its checksum
    let empty = trm_kinematics::binary_bytes(
        path,
        &(),
        trm_roadmap::CHECKPOINT_FORMAT,
        trm_roadmap::CHECKPOINT_VERSION,
    )
    .expect("a header");
    let mut bytes = empty[..empty.len() - 4].to_vec();
    bytes.extend_from_slice(content);
    bytes.extend(crc32fast::hash(&bytes).to_le_bytes());
    if let Ok(checkpoint) = trm_roadmap::Checkpoint::from_bytes(&bytes, path) {
        let written = checkpoint.to_bytes(path).expect("a checkpoint that reads is written");
        let again = trm_roadmap::Checkpoint::from_bytes(&written, path).expect("and reads back");
        assert_eq!(format!("{checkpoint:?}"), format!("{again:?}"));
    }
});
