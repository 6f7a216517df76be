/* Anchors the drape shared library target; every symbol comes from drape_core (whole archive). */
typedef int drape_shared_library_anchor_unused;
