"""Recordings read back: the reader, replay, report."""
