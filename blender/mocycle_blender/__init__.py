"""placeholder"""
def register():
    import mocycle
    print("REGISTER", mocycle.__file__)
def unregister():
    pass
