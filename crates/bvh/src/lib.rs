//! bvh (under construction)
