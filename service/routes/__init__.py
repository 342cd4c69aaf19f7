"""The service's routers, one per concern: curves (the model), design (geometry only), operations."""
