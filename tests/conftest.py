from hypothesis import settings

# The same examples on every run (CI must not flake); no example database between runs.
settings.register_profile("hrgtc", derandomize=True, database=None, deadline=None)
settings.load_profile("hrgtc")
