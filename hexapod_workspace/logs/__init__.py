"""MCAP logs in the rosbag2 form: type store, result <-> message fields, writer, reader, summary.

Adds mcap and rosbags to the core; imports nothing from :mod:`hexapod_workspace.cli` or
:mod:`hexapod_workspace.ros`.
"""
