//! Rays, shapes and the BVH of Spectrace (being written).
