"""The chains that join the stages: soaks and ramps to a model file, the demo.

* :mod:`hrgtc.pipeline.calibration` -- soaks + ramps (+ rate tables) -> the model file of
  one axis or every axis of an instrument, bias and scale factor (like pvlib's
  ``ModelChain``: one chain for one array or several, one result type);
* :mod:`hrgtc.pipeline.axis_calibration` -- one axis of it: thermometer and drift model;
* :mod:`hrgtc.pipeline.holdout` -- the end of a drift file held out for validation;
* :mod:`hrgtc.pipeline.demo` -- the paper's campaign end to end.

Nothing is imported here, so importing one chain does not load the others.
"""
