"""Every figure as a matplotlib ``Figure``, one implementation for the results' ``.plot()`` methods and for the
HTML report (``reporting/`` composes them into pages, with their captions).

A layer low in the package (docs/architecture.md#layers-of-the-package): it imports the models and the errors
only, and reads results by their fields (a ``SimulationResult``, a ``ValidationResult``'s predictions, a fit's
``to_dict()``), so that the results import it downward. Matplotlib is imported when a figure is drawn, not with
the package. The modules: ``plots.py`` (the visual language, measured against predicted, errors against
temperature), ``friction_plots.py`` (a simulation over time and its hysteresis, force data against position),
``fit_plots.py`` (a fit's laws and overview), ``study_plots.py`` (heated runs, closed loops), ``units.py`` (axis
units chosen from the data).
"""
