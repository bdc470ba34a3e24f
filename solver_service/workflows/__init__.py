"""Workflows and documents: floor 2 of rockmech, between the maths and the front ends.

Floor 2 holds three packages in an order (``tests/test_architecture.py``): ``report``
(renders documents), then this package (the analyses and their documents, which imports
``report``, never the other way round), then ``demo``. Each module is named for a domain
noun:

- ``inputs``: reading what users give (records with format detection, constants files,
  scenes with their specs);
- ``adapter``: validated constants (``shared_schema``) turned into the solver's models;
- ``documents``: JSON-ready documents of every analysis (pulse, record, envelope, boundary,
  history), the ones ``rockmech ... --json`` prints and the service returns;
- ``pulse``: the pulse analysis, apart so that a pulse loads the exact solver and no more
  (``documents`` re-exports it);
- ``scaling``: scale factors of records up the structure and the batched runs that use them;
- ``codecheck``: the check document (the Circolare 2019 §C8.7.1 checks on a site);
- ``assess``: the code checks beside the rocking dynamics (the check and assessment
  documents);
- ``verdict``: one verdict per mechanism and one for the building, from those documents;
- ``retrofit`` and ``retrofit_files``: the least tie force that makes a failing mechanism
  pass, and its ``retrofit.json``;
- ``search``: the façade search's run, ranking and files;
- ``ida``: incremental dynamic analysis, locally or on a Dask cluster (a package: ``plan``,
  ``task``, ``local``, ``dask``, ``peaks``, ``document``, ``run``);
- ``pages``: the analyses of the HTML pages (``rockmech report``, ``rockmech assess -o``),
  which ``solver_service.report`` then renders;
- ``tables``: constants tables (one mechanism per row) read into a constants file;
- ``limits``: a request's size limits and the estimate of its work;
- ``units``: the units block and producing version every JSON document carries;
- ``outputs``: files written from documents (JSON, CSV, PNG), atomically;
- ``rundir``: a run's output folder, whose own files rockmech replaces as a set.

The CLI, the REST service and the Rhino flows all build their documents here, so they agree.
Nothing here imports a front end; the maths below never imports this package.

Units: frequencies in Hz, pulse amplitudes and PGA in g (names end in ``_g``), SI otherwise.
"""
