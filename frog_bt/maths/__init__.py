"""Sans-I/O maths of the tour: the engagement meter and zone geometry."""
