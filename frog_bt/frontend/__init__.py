"""The UDP link to the content front end (CONTRACT §2)."""
