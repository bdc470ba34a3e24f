"""Workflows and documents: the third floor of rockmech, between the maths and the front ends.

Each module is named for a domain noun:

- ``inputs``: reading what users give (records with format detection, constants files,
  scenes with their specs);
- ``documents``: JSON-ready documents of every analysis (pulse, record, envelope, boundary,
  history), the ones ``rockmech ... --json`` prints and the service returns;
- ``pulse``: the pulse analysis, apart so that a pulse loads the exact solver and no more
  (``documents`` re-exports it);
- ``scaling``: scale factors of records up the structure and the batched runs that use them;
- ``outputs``: files written from documents (JSON, CSV, PNG), atomically.

The CLI, the REST service and the Rhino flows all build their documents here, so they agree.
Nothing here imports a front end; the maths below never imports this package.

Units: frequencies in Hz, pulse amplitudes and PGA in g (names end in ``_g``), SI otherwise.
"""
