"""drake_entry: atmospheric-entry guidance design and analysis on Drake."""
__version__ = "0.1.0"
