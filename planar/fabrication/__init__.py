"""fabrication."""
