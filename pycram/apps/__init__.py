"""The apps layer: the command line (:mod:`pycram.apps.cli`), the thesis demo and the scenarios
(:mod:`pycram.apps.demos`), and experiments over many runs (:mod:`pycram.apps.experiments`).

May import: everything. Nothing else imports the apps.
"""
