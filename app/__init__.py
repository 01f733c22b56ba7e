"""partlab app."""
