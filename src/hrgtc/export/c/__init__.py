"""The C99 text of the firmware export, one module per piece.

``plan`` (the numbers to print, validated from the model), ``types`` (the C floating
type: double or float), ``expr`` (term expressions, comment text), ``header`` (the
header of both builds, one template), ``text`` (the README block and the double
build's header), ``source`` (the ``.c`` file of both builds, one body printed in the
build's type), ``variables`` (the inputs and code of the drift variables beyond f and
df), ``rate_filter`` (the causal df/dt filter), ``thermometer`` (the inverse of the
thermometer), ``scale`` (the scale-factor correction), ``step`` (the tail of
``step()``), ``single`` (the float32 build's README sections and header) and
``float32`` (its constants and numpy mirror).
:func:`hrgtc.export.export_c` writes them.
"""
