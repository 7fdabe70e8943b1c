"""Bags as records and files, whatever their messages: MCAP and rosbag2 sqlite3 read and written.

Nothing here decodes a message (that is `..cdr`'s, above); modules are imported by name, so
that a command loads only the readers it uses.
"""
