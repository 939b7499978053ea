"""Tools around the tour: render a tree, record and replay a tour, summarise it."""
