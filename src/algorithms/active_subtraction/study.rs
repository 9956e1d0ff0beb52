//! Density study (seed 003 §V-B1).
