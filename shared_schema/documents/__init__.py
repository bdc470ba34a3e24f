"""One typed model per analysis document, defined once (issue #38).

Each module holds one document: ``pulse``, ``boundary``, ``envelope``, ``history``,
``record``, ... Every document derives from ``base.Document``: it refuses unknown keys,
starts with ``rockmech_version`` and ``units``, and has one JSON form, ``to_dict()``, which
``rockmech ... --json``, the files beside a run, the REST service and Hops all write. The
workflows (``solver_service.workflows``) build them; ``rockmech`` returns them.

The modules are imported on use (nothing here), so a command loads only its own document.
"""
