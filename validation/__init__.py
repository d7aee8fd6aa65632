"""Validation reports: the models side by side, against exact solutions, the FEM reference and the
paper (`python -m validation report`)."""
