(define (problem p) (:domain sub)
  (:objects t - tiago k h - place)
  (:init (at t k) (link k h))
  (:goal (at t h)))
