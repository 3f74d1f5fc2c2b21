"""The C99 text of the firmware export, one module per piece.

``plan`` (the numbers to print, validated from the model), ``types`` (the C floating
type: double or float), ``expr`` (term expressions, comment text), ``header`` (the
header of both builds, one template), ``text`` (README block and source of the double
build), ``variables`` (the inputs and code of the drift variables beyond f and df),
``rate_filter`` (the causal df/dt filter), ``thermometer`` (the inverse of the
thermometer), ``scale`` (the scale-factor correction), ``step`` (the tail of
``step()``), ``single`` and ``float32`` (the float32 build and its numpy mirror).
:func:`hrgtc.export.export_c` writes them.
"""
