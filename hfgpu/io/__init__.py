"""Results files (HDF5) and live or recorded views (Rerun)."""
