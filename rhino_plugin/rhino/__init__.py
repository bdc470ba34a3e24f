"""Rhino 8 glue: the command scripts, the Rhino prompter, document conversion, drawing.

Everything here imports RhinoCommon (``Rhino``, ``Eto``, ``scriptcontext``) and runs only
inside Rhino 8 (CPython 3.9). It stays thin: the prompt flows, the spec and the constants
are computed by ``rhino_plugin.flows`` and ``cad_maths.mechanisms``, which are tested
headless. Type-checked against RhinoCommon with pyright and ``rhino-stubs-typed``.
"""
