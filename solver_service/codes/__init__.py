"""The building codes, apart from the rocking solver: what a code says, as numerics.

- ``circ2019``: the kinematic checks of the Circolare 21 gennaio 2019 n. 7 (C8.7.1.2.1), the
  checks rockmech runs by default (theory §11);
- ``circ2009``: the 2009 forms (Circolare 617/2009 C8A.4), kept for comparison, and the
  virtual-work quantities both use (``VirtualWork``, ``participating_mass``);
- ``hazard``: the elastic response spectra of NTC 2018 and EN 1998-1;
- ``floor_spectra``: the floor spectra and displacements of the Circolare 2019 (C7.2.3);
- ``scale_factors``: the code and paper scale factors for the acceleration at a height in a
  structure (EN 1998-1, NZS 1170.5, the paper's Eq. 28; theory §7.3–7.4).

Floor 1 (maths), beside ``cad_maths``: it imports ``shared_schema`` and the solver's helpers
in ``solver_service.core`` (``model``'s checks, ``spectra``, ``amplification``), never the
other way round; no pydantic, no Rhino.
"""
