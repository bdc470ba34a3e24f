"""The commands' prompt flows, free of Rhino: they ask a :class:`Prompter` and build specs.

Rhino answers the questions with its command-line prompts and Eto dialogs
(``rhino_plugin.rhino``); tests answer them with scripted replies over a ``.3dm`` scene read
by rhino3dm. Runs inside Rhino 8 (CPython 3.9).
"""
