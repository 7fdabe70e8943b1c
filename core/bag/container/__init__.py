"""Bags as records and files, whatever their messages: MCAP and rosbag2 sqlite3 read and written.

Nothing here decodes a message (that is `..cdr`'s, above); modules are imported by name, so
that a command loads only the readers it uses.
"""

from typing import TYPE_CHECKING

from ..._faces import lazy_exports

if TYPE_CHECKING:
    from .chunk_codecs import Skips
    from .mcap_scan import DAMAGE, Contents, Kept, open_mcap, scan
    from .mcap_verify import verify_mcap
    from .summary import BagSummary, TopicSummary, summarize
    from .topic_reader import Channel, byte_rows, read_topic
    from .writer import BagStream, atomic_file, open_bag, output_problem, staged_file, write_bag

__all__ = [
    "BagStream",
    "BagSummary",
    "Channel",
    "Contents",
    "DAMAGE",
    "Kept",
    "Skips",
    "TopicSummary",
    "atomic_file",
    "byte_rows",
    "open_bag",
    "open_mcap",
    "output_problem",
    "read_topic",
    "scan",
    "staged_file",
    "summarize",
    "verify_mcap",
    "write_bag",
]

__getattr__ = lazy_exports(__name__, {
    "BagStream": "writer",
    "BagSummary": "summary",
    "Channel": "topic_reader",
    "Contents": "mcap_scan",
    "DAMAGE": "mcap_scan",
    "Kept": "mcap_scan",
    "Skips": "chunk_codecs",
    "TopicSummary": "summary",
    "atomic_file": "writer",
    "byte_rows": "topic_reader",
    "open_bag": "writer",
    "open_mcap": "mcap_scan",
    "output_problem": "writer",
    "read_topic": "topic_reader",
    "scan": "mcap_scan",
    "staged_file": "writer",
    "summarize": "summary",
    "verify_mcap": "mcap_verify",
    "write_bag": "writer",
})
