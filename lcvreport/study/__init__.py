"""Studies at scale (docs/studies.md): a study file's cases, computed in batches on Dask,
written as Parquet chunks; read back as one table.

``spec``     the study file: base vehicle, factors, design, measures; the cases
``compute``  the measures of a chunk of cases (batched over the cases)
``run``      ``lcv study``: chunks on a Dask scheduler, Parquet written atomically, a manifest,
             resume, interruption, progress
``results``  :func:`read_study` and :func:`study_case`
"""
