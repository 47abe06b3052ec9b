//! Hydrodynamic mobilities and Brownian displacements (placeholder; being written).
