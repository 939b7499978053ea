"""Tour trees: the leaf registry, project-clock decorators and the YAML loader."""
