"""One module per discrete energy: energy, gradient and Hessian together, vectorised."""
