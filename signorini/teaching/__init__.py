"""The library side of the tutorials (docs/tutorials/): the dual function, a two-contact-point
model, synthetic problems and the tutorials' figures."""
