# core/character: the character tier (above the foundations, below algorithms and io): animated
# characters (node hierarchy, skins, clips) and their evaluation, joint sets, skinning, prop tracks.
list(APPEND MM_CORE_SOURCES
  core/character/animated_character.cpp
  core/character/joint_set.cpp
  core/character/skinning.cpp
  core/character/prop_tracks.cpp
  core/character/morph_basis.cpp)
