"""Recordings on disk: the JSONL interchange format and its readers."""
