"""What every numba-compiled kernel of the science shares: the worker threads and the lock their parallel
launches take (:mod:`monitor.compiled.threads`)."""
