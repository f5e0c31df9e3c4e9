//! Where a flower's organs go, as data: the bracketed parametric
//! L-systems and turtle of `lsystem-bezier-flower.txt` §2–§3.

pub mod lsystem;
pub mod turtle;

#[cfg(test)]
mod tests;
