"""partlab labelling."""
