"""The apps layer: the command line (:mod:`pycram.apps.cli`), the thesis demo and the scene
pictures (:mod:`pycram.apps.demos`), the scenarios (:mod:`pycram.apps.scenarios`, one package
each) and experiments over many runs (:mod:`pycram.apps.experiments`).

May import: everything. Nothing else imports the apps.
"""
