"""partlab tracking."""
