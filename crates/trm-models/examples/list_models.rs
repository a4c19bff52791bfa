//! Every embedded model: motors, joints, links, named frames, groups and postures.
//!
//! `cargo run -p trm-models --example list_models`

fn main() {
    for name in trm_models::NAMES {
        let m = trm_models::by_name(name).expect("every listed model loads");
        println!(
            "{name:<16} {:>3} motors {:>3} joints {:>3} links {:>3} frames; groups: {}; postures: {}",
            m.motors().len(),
            m.num_joints(),
            m.num_links(),
            m.named_frames().len(),
            m.groups().map(|(g, _)| g).collect::<Vec<_>>().join(" "),
            m.posture_names().collect::<Vec<_>>().join(" ")
        );
    }
}
