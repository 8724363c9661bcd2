(define (problem load) (:domain load-in)
  (:objects b t l)
  (:init (box b) (truck t) (at b l) (at t l))
  (:goal (in b t)))
