"""The `curve-vae` commands, one module per group, each beside what it drives: `data` (dataset), `train`
(train, average), `model` (export, evaluate, triton), `generate` (sample, augment, fit, revolve). Each module's
`register` adds its subcommands to the parser; each command imports what it needs when it runs, so the
offline commands and `serve` work in the base install (no torch).
"""
