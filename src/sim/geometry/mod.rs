//! Pure geometry and mechanics, apart from any system: circles ([`circle`]), free flight under
//! gravity ([`flight`]), the arena's walls ([`wall`]) and putting a ball back inside them
//! ([`contain`]), impulses ([`impulse`]), the uniform grid ([`grid`]) and the touching pairs it
//! finds ([`pairs`]). Plain functions over plain values, each with its unit tests; every stage,
//! the aiming guide, scene placement and the measurements are built from them.

pub mod circle;
pub mod contain;
pub mod flight;
pub mod grid;
pub mod impulse;
pub mod pairs;
pub mod wall;

pub use circle::{Circle, ContactGeometry};
pub use wall::Wall;
