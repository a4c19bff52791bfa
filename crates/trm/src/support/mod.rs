//! What several commands share: none of them imports another command.

pub mod configs;
pub mod description;
pub mod scene;
pub mod taskmap;
pub mod timing;
