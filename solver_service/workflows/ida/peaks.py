"""The per-run peaks of an IDA, streamed into a Parquet file as the tasks finish."""

from __future__ import annotations

import os
import secrets
from pathlib import Path
from typing import Any

import numpy as np

from shared_schema.atomic import temp_name
from shared_schema.extras import require
from shared_schema.rules import IM_MEASURES
from shared_schema.version import __version__

__all__ = ["ROW_GROUP_ROWS", "PeakWriter"]

#: Rows of the peaks file gathered before they are written as one row group.
ROW_GROUP_ROWS = 1 << 20


class PeakWriter:
    """Per-run peaks streamed into a Parquet file, one row per record × mechanism × level.

    Written under a temporary name beside the target (``shared_schema.atomic.temp_name``)
    and renamed over it when complete; removed if the run stops.
    """

    def __init__(
        self,
        path: Path,
        records: list[str],
        mechanisms: list[str],
        levels: list[float],
        measure: str,
    ) -> None:
        self.pa = require("pyarrow", "parquet", "for the per-run peaks of ida")
        self.pq = require("pyarrow.parquet", "parquet", "for the per-run peaks of ida")
        self.path = path
        self.tmp = path.parent / temp_name(path.name, os.getpid(), secrets.token_hex(4))
        self.records = self.pa.array(records, type=self.pa.string())
        self.mechanisms = self.pa.array(mechanisms, type=self.pa.string())
        self.levels = np.asarray(levels)
        pa = self.pa
        dictionary = pa.dictionary(pa.int32(), pa.string())
        self.schema = pa.schema(
            [
                ("record", pa.int32()),
                ("record_name", dictionary),
                ("mechanism", dictionary),
                ("level", pa.float64()),
                ("peak_ratio", pa.float64()),
                ("overturned", pa.bool_()),
                ("error_estimate", pa.float64()),
                ("status", pa.int8()),
            ],
            metadata={
                "intensity_measure": measure,
                "units": IM_MEASURES[measure],
                "rockmech": __version__,
            },
        )
        self.writer = self.pq.ParquetWriter(str(self.tmp), self.schema, compression="zstd")
        self.buffer: list[Any] = []
        self.buffered = 0
        self.rows = 0

    def add(self, part: dict[str, Any]) -> None:
        """Add the runs of one task (``run_task`` with peaks)."""
        pa, peaks = self.pa, part["peaks"]
        n_rec, n_mech, n_lev = peaks["peak_ratio"].shape
        record = np.repeat(np.asarray(part["records"][:n_rec], dtype=np.int32), n_mech * n_lev)
        mech = np.tile(np.repeat(np.arange(n_mech, dtype=np.int32), n_lev), n_rec)
        level = np.tile(self.levels[part["lo"] : part["hi"] : part["step"]], n_rec * n_mech)
        columns = [
            pa.array(record),
            pa.DictionaryArray.from_arrays(pa.array(record), self.records),
            pa.DictionaryArray.from_arrays(pa.array(mech), self.mechanisms),
            pa.array(level),
            pa.array(peaks["peak_ratio"].ravel()),
            pa.array(peaks["overturned"].ravel()),
            pa.array(peaks["error_estimate"].ravel()),
            pa.array(peaks["status"].ravel().astype(np.int8)),
        ]
        self.buffer.append(pa.Table.from_arrays(columns, schema=self.schema))
        self.buffered += record.size
        if self.buffered >= ROW_GROUP_ROWS:
            self._flush()

    def _flush(self) -> None:
        if self.buffer:
            self.writer.write_table(self.pa.concat_tables(self.buffer))
            self.rows += self.buffered
            self.buffer, self.buffered = [], 0

    def close(self) -> int:
        """Write what is left, rename the file into place; return the number of rows."""
        self._flush()
        self.writer.close()
        with open(self.tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(self.tmp, self.path)
        return self.rows

    def abort(self) -> None:
        """Close and remove the unfinished file."""
        try:
            self.writer.close()
        finally:
            self.tmp.unlink(missing_ok=True)
