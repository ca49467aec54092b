//! molecule (under construction)
