(define (problem through) (:domain derived-door)
  (:objects k h)
  (:init (at k) (link k h))
  (:goal (at h)))
