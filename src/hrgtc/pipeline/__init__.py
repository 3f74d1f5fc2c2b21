"""The chains that join the stages: soaks and ramps to a model file, an instrument, the demo.

* :mod:`hrgtc.pipeline.calibration` -- soaks + ramps -> one unit's model file (like
  pvlib's ``ModelChain``: one object that orchestrates the sub-models);
* :mod:`hrgtc.pipeline.instrument` -- every axis of an instrument, bias and scale factor;
* :mod:`hrgtc.pipeline.holdout` -- the end of a drift file held out for validation;
* :mod:`hrgtc.pipeline.demo` -- the paper's campaign end to end.

Nothing is imported here, so importing one chain does not load the others.
"""
