//! Tests of the CSI edge.
