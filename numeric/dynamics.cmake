# Hybrid dynamics on the validated evaluators: certified event location
# (witness functions), dividing lines, the hybrid simulator, limit cycles.
target_sources(backlash_numeric PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/src/first_crossing.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/scales.cpp             # what double precision can compute, checked first
  ${CMAKE_CURRENT_LIST_DIR}/src/segment_dynamics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/gap_events.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/linear_flight.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/dividing_lines.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/hybrid_simulation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/limit_cycle.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/validated_family.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/sweep.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/settle.cpp             # the settle time of a step response (maps)
  ${CMAKE_CURRENT_LIST_DIR}/src/odeint_simulation.cpp    # odeint: the independent cross-check simulator
  # Effects the thesis left out (docs/effects.md)
  ${CMAKE_CURRENT_LIST_DIR}/src/effects.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/effect_modes.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/effects_engine.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/effects_simulation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/effects_validation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/effects_limit_cycle.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/effects_delay.cpp      # odeint: the delayed model (method of steps)
  ${CMAKE_CURRENT_LIST_DIR}/src/odeint_effects_simulation.cpp)  # odeint: the independent simulator with effects
find_package(Threads REQUIRED)
target_link_libraries(backlash_numeric PUBLIC Threads::Threads)
