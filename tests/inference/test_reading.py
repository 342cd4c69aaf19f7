"""inference.reading: one value for how curves are read, "auto" made the model's own."""

from curve_vae.inference.manifest import ReadingSpec
from curve_vae.inference.reading import Reading


def test_auto_is_the_models_reading_and_explicit_values_stay():
    canonical = ReadingSpec(pose="canonical", spacing="parameter")
    assert Reading().resolved(canonical) == Reading(pose="canonical", spacing="parameter")
    assert Reading().resolved(ReadingSpec()) == Reading(pose="search", spacing="search")
    assert Reading(pose="as_is", spacing="natural").resolved(canonical) == Reading(pose="as_is", spacing="natural")
    assert Reading(frame="model").resolved(canonical).pose == "as_is"  # points in the plane keep their pose
    assert Reading(pose="search").resolved(canonical).searches and not Reading().resolved(canonical).searches
    assert Reading(refine=3).key != Reading().key
