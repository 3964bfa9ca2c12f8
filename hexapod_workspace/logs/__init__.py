"""MCAP logs in the rosbag2 form: type store, result <-> message fields, writer, reader, summary.

Adds mcap and rosbags to the core; imports nothing from :mod:`hexapod_workspace.cli` or
:mod:`hexapod_workspace.ros`. One module per concern:

- :mod:`.typestore`: rosbags' Jazzy store plus our interfaces; schema text, type hashes, QoS text;
- :mod:`.fields`: field dicts <-> messages, CDR;
- :mod:`.messages`: results of the core -> message fields (one mapping for the node and the CLI);
- :mod:`.writer`: :class:`LogWriter`;
- :mod:`.reader`: :func:`read_log`, :func:`iter_log`, :func:`recover_log`;
- :mod:`.summary`: what a log holds (workspaces, pose checks), for replay.
"""

from .fields import build_message, deserialize, message_to_fields, serialize
from .reader import (
    LogContents,
    LogMessage,
    TopicInfo,
    iter_log,
    read_log,
    recover_log,
)
from .typestore import (
    INTERFACE_PACKAGE,
    REQUEST_QOS,
    RESULT_QOS,
    SERVICE_QOS,
    get_typestore,
    message_definition,
    qos_profile_text,
    recorded_type,
    service_part,
    service_topics,
    store_name,
    type_hash,
)
from .writer import (
    DEFAULT_CHUNK_SIZE,
    DEFAULT_FLUSH_INTERVAL,
    DEFAULT_FLUSH_MESSAGES,
    LogWriter,
    run_log_path,
)

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "DEFAULT_FLUSH_INTERVAL",
    "DEFAULT_FLUSH_MESSAGES",
    "INTERFACE_PACKAGE",
    "REQUEST_QOS",
    "RESULT_QOS",
    "SERVICE_QOS",
    "LogContents",
    "LogMessage",
    "LogWriter",
    "TopicInfo",
    "build_message",
    "deserialize",
    "get_typestore",
    "iter_log",
    "message_definition",
    "message_to_fields",
    "qos_profile_text",
    "read_log",
    "recorded_type",
    "recover_log",
    "run_log_path",
    "serialize",
    "service_part",
    "service_topics",
    "store_name",
    "type_hash",
]
