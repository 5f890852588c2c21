//! BRDFs of the rendering family (R-H, R-A, R-rec).
