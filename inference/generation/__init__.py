"""New curves from the model: drawn from a latent distribution (`sampling`, with the learned `prior` and priors
fitted to users' curves, `named_priors`), mixed between given curves (`mixing`, `augmenting`), and around one curve
(`exploring`)."""
