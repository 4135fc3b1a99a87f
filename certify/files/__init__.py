"""Files of :mod:`qualgrasp.certify`: reading grasp sets and results, writing them, the results
schema, safe writes.

* :mod:`.reader`: the one reader of grasp sets and results (JSON Lines or Parquet, recognised by
  content, streamed in fixed-size chunks; a bad line is an error row, never a crash);
* :mod:`.columns`: any Arrow layout of grasps as validated columns;
* :mod:`.writers`: grasp sets and results rows written by extension;
* :mod:`.results`: the results columns and their Arrow schema;
* :mod:`.outputs`: how every output is written (a temporary renamed at the end, a lock, never an
  input, a FIFO or a device).
"""

from .columns import GraspColumns, grasp_columns
from .outputs import OutputLock, atomic_output, check_output, lock_output, write_lines
from .reader import (GRASP_SCHEMA, Chunk, chunk_values, count_grasps, grasps_table, input_format, is_parquet,
                     iter_chunks, json_lines, read_results, rows_to_table, table_to_rows, table_values)
from .results import COLUMNS, NAMES, RESULT_SCHEMA, Column
from .writers import write_grasps, write_rows

__all__ = [
    "is_parquet", "input_format", "json_lines", "Chunk", "iter_chunks", "count_grasps", "read_results",
    "chunk_values", "table_values", "GRASP_SCHEMA", "grasps_table", "rows_to_table", "table_to_rows",
    "GraspColumns", "grasp_columns",
    "write_grasps", "write_rows",
    "Column", "COLUMNS", "NAMES", "RESULT_SCHEMA",
    "atomic_output", "check_output", "lock_output", "OutputLock", "write_lines",
]
