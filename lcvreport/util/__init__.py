"""Small utilities shared by the layers: an LRU cache and numerics that need only numpy."""
