"""ROS 2 messages as CDR bytes: the writer, the ros2msg definitions moveplan ships, and the encoders.

The schema-driven encoder (generic) writes any message given as a dict (messages); the
hand-written twins (bulk, joint_state) write the big, numerous ones with bulk float packing,
to the same bytes. Nothing here knows a file format (that is `..container`'s, below).
"""
