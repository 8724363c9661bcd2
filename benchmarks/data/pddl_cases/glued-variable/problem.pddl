(define (problem hop) (:domain glued)
  (:objects r k h)
  (:init (robot r) (at r k) (link k h))
  (:goal (at r h)))
