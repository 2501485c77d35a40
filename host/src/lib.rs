//! Host-side library: map loading, storage on the heap, output.
