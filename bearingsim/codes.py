"""Integer codes with one meaning in both models, their kernels and the archive (a leaf module)."""

FACE_REAR = 0   # the pocket's rear face: the cage drags a lagging roller (I_dec)
FACE_FRONT = 1  # the pocket's front face: the roller pushes the cage (I_acc)
FACE_NAMES = ("rear", "front")  # indexed by the face code
