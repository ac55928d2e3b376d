"""The collocation: VIIRS swaths prepared in 3-D and the compiled cone and disc kernels."""
