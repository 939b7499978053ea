"""Sub-commands of the frog-bt CLI."""
