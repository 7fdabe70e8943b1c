"""The `moveplan` command line: a thin shell that parses flags, calls core once, renders, exits with a code."""
