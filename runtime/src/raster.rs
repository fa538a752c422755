//! Raster (iso-plane) planning for 3-axis mills: being written.
