"""Evaluation of generated curves, outside the serving core: the field's generation metrics (`generation`) and a
prior's samples measured against held-out curves with them (`prior_report`, `curve-vae evaluate-prior`)."""
