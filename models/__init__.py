"""partlab models."""
