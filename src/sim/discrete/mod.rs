//! The discrete mode, the tutorial's method: move every ball and contain it in the arena
//! (stage 1, [`movement`](super::movement)), find every touching pair ([`detect`], stage 2),
//! then exchange momentum along each contact normal and push the pair apart ([`resolve`],
//! stage 3). Fast balls can pass through each other; the continuous mode is the cure.

pub mod detect;
pub mod parts;
pub mod resolve;
