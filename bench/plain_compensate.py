"""The baseline of ``hrgtc compensate`` file to file: a plain pyarrow streaming script.

    python bench/plain_compensate.py MODEL.json RUN.parquet OUTPUT.parquet

Read Parquet batches, evaluate the model with hrgtc's fused kernel, write Parquet; no
validation, no spike filter, no motion pass, no fsync. Written as a user would with
pyarrow and numpy, with pyarrow's fastest writer options for float columns
(uncompressed, no dictionary: less work per row than hrgtc's byte-stream split, LZ4 and
page checksums, for a file 1.6x larger; pyarrow's defaults, snappy and dictionary, cost
2.7x more), so it is the strictest baseline. ``bench/bench_compensate.py`` (one process,
imports not timed) and ``bench/bench_commands.py`` (whole commands) time it.
"""

from __future__ import annotations

import sys


def plain_script(model_path: str, source: str, output: str, rows: int = 1 << 20) -> int:
    """The baseline: read, compensate with the fused kernel, write; no validation, no fsync."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    from hrgtc.compensate import OUTPUT_COLUMNS
    from hrgtc.compensate import _kernel as kernel
    from hrgtc.model import load_model

    model = load_model(model_path)
    variables = tuple(dict.fromkeys(("f", "df", *model.drift.variables)))
    plan = kernel.plan(model.drift, model.thermometer, variables)
    state, counts = kernel.new_state(), np.zeros(4, dtype=np.int64)
    extremes = kernel.new_extremes()
    writer = None
    done = 0
    for batch in pq.ParquetFile(source).iter_batches(batch_size=rows):
        out = {name: np.empty(batch.num_rows) for name in OUTPUT_COLUMNS}
        housing = batch.column("housing_c").to_numpy() if plan.needs_housing else None
        kernel.run(plan, state, (batch.column("time_s").to_numpy(),
                                 batch.column("freq_hz").to_numpy(),
                                 batch.column("rate_dph").to_numpy(), housing),
                   out, counts, extremes)
        table = pa.Table.from_batches([batch])
        for name in OUTPUT_COLUMNS:
            table = table.append_column(name, pa.array(out[name]))
        if writer is None:
            writer = pq.ParquetWriter(output, table.schema, compression="none",
                                      use_dictionary=False)
        writer.write_table(table)
        done += batch.num_rows
    if writer is not None:
        writer.close()
    return done


if __name__ == "__main__":
    plain_script(*sys.argv[1:4])
