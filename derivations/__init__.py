"""Symbolic derivations of apair: each module derives closed forms and returns kernel specs."""
